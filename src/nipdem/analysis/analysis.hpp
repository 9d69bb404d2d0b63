// Umbrella header for the engine-independent analysis helpers of the experiments.
#pragma once
#include "nipdem/analysis/fit.hpp"
#include "nipdem/analysis/reduction.hpp"
#include "nipdem/analysis/steady.hpp"
#include "nipdem/analysis/vo.hpp"
#include "nipdem/analysis/report.hpp"
