// The field maps shipped in examples/fields/ cover everything toner can reach in their presets'
// nip (window, roller pits, up to the drum), so `magnet.field = "map"` runs on the preset
// (issue 21; before, the maps stopped at y = 0 and the setup refused them, rightly).
#include <gtest/gtest.h>

#include <string>

#include "nipdem/nip/nip.hpp"
#include "nipdem/nip/presets.hpp"

TEST(FieldMap, ShippedMapsCoverThePresets) {
  for (const auto& [preset, file] : {std::pair{"black", "knife_black_25um.csv"}, std::pair{"color", "pole_color_25um.csv"}}) {
    SCOPED_TRACE(preset);
    const std::string map = std::string(NIPDEM_SOURCE_DIR) + "/examples/fields/" + file;
    const auto cfg = nipdem::nip::parse_nip_config(
        nipdem::nip::preset_text(preset), std::string("preset:") + preset,
        {"magnet.field=\"map\"", "magnet.map_file=\"" + map + "\"", "output.vtk=false", "run.threads=2"});
    nipdem::nip::NipRun run(cfg);  // the setup checks the map against the reachable region
    ASSERT_GT(run.sim().bodies().x.size(), 10u);
    run.advance_to(50 * run.time_step().dt);  // and the threaded field pass finds every body inside it
    EXPECT_GT(run.sim().time(), 0.0);
  }
}
