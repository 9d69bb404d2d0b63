// Moved to nipdem/nip/nip_config.hpp (the nip scenario, docs/ARCHITECTURE.md). This forwarding header
// keeps fuzz/ building until its includes name the new place; do not include it in new code.
#pragma once
#include "nipdem/nip/nip_config.hpp"
