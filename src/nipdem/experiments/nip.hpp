// Moved to nipdem/nip/nip.hpp (the nip scenario, docs/ARCHITECTURE.md). This forwarding header
// keeps fuzz/ building until its includes name the new place; do not include it in new code.
#pragma once
#include "nipdem/nip/nip.hpp"
