// Umbrella header for the engine-independent analysis helpers of the experiments.
#pragma once
#include "nipdem/experiments/analysis_fit.hpp"
#include "nipdem/experiments/analysis_reduction.hpp"
#include "nipdem/experiments/analysis_steady.hpp"
#include "nipdem/experiments/analysis_vo.hpp"
#include "nipdem/experiments/analysis_report.hpp"
