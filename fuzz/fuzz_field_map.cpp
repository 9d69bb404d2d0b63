// A magnet field-map CSV (x_m,y_m,Bx_T,By_T with units), then one lookup at its centre.
#include "fuzz_common.hpp"
#include "nipdem/io/field_map.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return nipdem::fuzz::run_one(data, size, [](const std::string& text) {
    const auto m = nipdem::io::FieldMap::from_csv(text, "fuzz.csv");
    m.at({0.5 * (m.x_min() + m.x_max()), 0.5 * (m.y_min() + m.y_max())});
  });
}
