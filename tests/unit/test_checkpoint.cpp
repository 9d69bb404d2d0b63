// Checkpoints that defend themselves (issue 21, docs/reliability.md): the CRC-32C check value,
// the frame refusing truncated / extended / damaged files, the engine refusing every
// inconsistent count or index even when the checksum is right (re-sealed payloads), and
// deterministic bytes (two identical runs, identical checkpoints).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <string>

#include "nipdem/core/crc32c.hpp"
#include "nipdem/core/error.hpp"
#include "nipdem/core/rng.hpp"
#include "nipdem/engine/simulation.hpp"
#include "nipdem/nip/nip.hpp"
#include "nipdem/nip/presets.hpp"
#include "nipdem/io/checkpoint_file.hpp"

using namespace nipdem;

namespace {
std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}
bool contains(const std::string& s, const std::string& needle) { return s.find(needle) != std::string::npos; }
}  // namespace

TEST(Crc32c, CheckValueAndChaining) {
  EXPECT_EQ(crc32c("123456789"), 0xE3069283u);  // RFC 3720 / iSCSI check value
  EXPECT_EQ(crc32c(""), 0u);
  EXPECT_EQ(crc32c("6789", crc32c("12345")), 0xE3069283u);
  // 32 zero bytes: RFC 3720 B.4 test vector
  EXPECT_EQ(crc32c(std::string(32, '\0')), 0x8A9136AAu);
}

TEST(CheckpointFrame, RoundTripAndEveryKindOfDamageIsRefused) {
  const std::string payload = "some state \x01\x02\x03 of 27 bytes.";
  const std::string blob = io::seal_checkpoint(payload);
  ASSERT_EQ(blob.size(), io::kCheckpointHeaderBytes + payload.size());
  EXPECT_EQ(io::open_checkpoint(blob, "f.bin"), payload);
  auto refused = [&](const std::string& b, const std::string& needle) {
    const std::string m = message_of([&] { io::open_checkpoint(b, "dir/f.bin"); });
    EXPECT_TRUE(contains(m, "dir/f.bin: ")) << m;
    EXPECT_TRUE(contains(m, needle)) << m;
  };
  refused(blob.substr(0, blob.size() - 1), "truncated");
  refused(blob.substr(0, 10), "not a nipdem checkpoint");
  refused("", "not a nipdem checkpoint");
  refused(blob + "x", "appended");
  std::string b = blob;
  b[io::kCheckpointHeaderBytes + 3] ^= 0x10;
  refused(b, "CRC-32C");
  b = blob;
  b[8] ^= 1;  // version
  refused(b, "header damaged");
  refused("NIPDEMRUN3" + std::string(100, '\0'), "older nipdem");
}

// ---- engine: re-sealed payloads with one field changed (the checksum cannot help there) ----
namespace {
engine::Simulation make_engine() {
  engine::EngineParams p;
  engine::Interaction ia;
  ia.contact.k = 56; ia.contact.gamma = 1e-8; ia.contact.ks = 16; ia.contact.mu_s = 0.47; ia.contact.mu_d = 0.19;
  p.interactions = {ia};
  p.dt = 1e-9;
  return engine::Simulation(p, {});
}
engine::Simulation filled_engine() {
  engine::Simulation sim = make_engine();
  Rng rng(5);
  for (int i = 0; i < 12; ++i) {
    engine::BodySpec s;
    s.offsets = {{0, 0}, {1.5e-6, 0}};
    s.radii = {1e-6, 1e-6};
    s.density = 1700;
    s.position = {(i % 4) * 3.2e-6, (i / 4) * 2.1e-6};
    s.angle = rng.uniform(0, 6.28);
    s.velocity = {rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1)};
    sim.add_body(s);
  }
  for (int k = 0; k < 30; ++k) sim.step();
  return sim;
}
// Element sizes of the engine's vectors in save order (checkpoint.cpp): 12 body doubles, id,
// first_disc, n_discs, tag, 12 disc doubles, body, wall_key, wall_eta, wall_slide, row_start,
// nbr, eta, slide.
constexpr int kElem[] = {8, 8, 8, 8, 8, 8, 8, 8, 8, 8, 8, 8, 8, 8, 8, 4, 4, 4, 8, 8, 8, 8, 8, 8, 8, 8, 8, 8, 8, 8, 4, 8, 8, 1, 4, 4, 8, 1};
// body x, y, vx, vy, theta, omega, cos theta, sin theta, fx, fy, torque, mass, inertia, size; id, ...
enum Vec { kBodyX = 0, kBodyCos = 6, kBodyMass = 11, kBodyId = 14, kFirstDisc = 15, kNDiscs = 16, kDiscX = 18, kDiscR = 24,
           kDiscBody = 30, kWallKey = 31, kRowStart = 34, kNbr = 35 };
// Offset of the count of vector v in an engine blob.
std::size_t vec_offset(const std::string& s, int v) {
  std::size_t at = 32;  // magic, time, step, next_id
  for (int k = 0; k < v; ++k) {
    std::uint64_t n;
    std::memcpy(&n, s.data() + at, 8);
    at += 8 + n * kElem[k];
  }
  return at;
}
template <class T> void poke(std::string& s, int v, std::size_t index, T value) {
  std::memcpy(s.data() + vec_offset(s, v) + 8 + index * sizeof(T), &value, sizeof(T));
}
std::uint64_t count_of(const std::string& s, int v) {
  std::uint64_t n;
  std::memcpy(&n, s.data() + vec_offset(s, v), 8);
  return n;
}
}  // namespace

TEST(EngineCheckpoint, EveryInconsistentCountOrIndexIsRefused) {
  const engine::Simulation sim = filled_engine();
  std::stringstream ss;
  sim.save(ss);
  const std::string good = ss.str();
  ASSERT_GT(count_of(good, kNbr), 5u) << "the test needs neighbour pairs";
  {  // the unchanged state loads and resumes bitwise
    engine::Simulation b = make_engine();
    std::istringstream in(good);
    b.load(in);
    engine::Simulation ref = filled_engine();
    for (int k = 0; k < 10; ++k) { b.step(); ref.step(); }
    for (std::size_t i = 0; i < ref.bodies().x.size(); ++i) EXPECT_EQ(ref.bodies().x[i], b.bodies().x[i]);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case { const char* what; std::function<void(std::string&)> change; const char* needle; };
  const std::vector<Case> cases = {
      {"first_disc out of range", [](std::string& s) { poke<int>(s, kFirstDisc, 1, 1000); }, "body 1 has discs"},
      {"first_disc negative", [](std::string& s) { poke<int>(s, kFirstDisc, 0, -3); }, "body 0 has discs"},
      {"n_discs zero", [](std::string& s) { poke<int>(s, kNDiscs, 0, 0); }, "body 0 has discs"},
      {"n_discs too large", [](std::string& s) { poke<int>(s, kNDiscs, 11, 3); }, "body 11 has discs"},
      {"disc owner", [](std::string& s) { poke<int>(s, kDiscBody, 0, 5); }, "owned by body 5"},
      {"body id duplicated", [](std::string& s) { poke<std::int64_t>(s, kBodyId, 1, 0); }, "body id[1]"},
      {"mass negative", [](std::string& s) { poke<double>(s, kBodyMass, 2, -1.0); }, "body mass[2]"},
      {"position NaN", [&](std::string& s) { poke<double>(s, kBodyX, 3, nan); }, "body x[3]"},
      {"orientation not a unit vector", [](std::string& s) { poke<double>(s, kBodyCos, 2, 0.5); }, "body orientation 2"},
      {"disc position inf", [&](std::string& s) { poke<double>(s, kDiscX, 0, INFINITY); }, "disc x[0]"},
      {"radius zero", [](std::string& s) { poke<double>(s, kDiscR, 4, 0.0); }, "disc r[4]"},
      {"wall key names no wall", [](std::string& s) { poke<std::int64_t>(s, kWallKey, 0, std::int64_t{3} << 40); }, "wall_key[0]"},
      {"row_start not monotone", [](std::string& s) { poke<int>(s, kRowStart, 1, 1 << 30); }, "row_start"},
      {"row_start[0] not 0", [](std::string& s) { poke<int>(s, kRowStart, 0, 1); }, "row_start[0]"},
      {"nbr out of range", [](std::string& s) { poke<int>(s, kNbr, 0, 1 << 20); }, "neighbour nbr[0]"},
      {"nbr negative", [](std::string& s) { poke<int>(s, kNbr, 1, -7); }, "neighbour nbr[1]"},
      {"body count larger", [](std::string& s) { const std::uint64_t n = count_of(s, kBodyX) + 1; std::memcpy(s.data() + vec_offset(s, kBodyX), &n, 8); }, "engine state"},
      {"body count huge", [](std::string& s) { const std::uint64_t n = 1ull << 40; std::memcpy(s.data() + vec_offset(s, kBodyX), &n, 8); }, "elements"},
      {"disc count smaller", [](std::string& s) { const std::uint64_t n = count_of(s, kDiscX) - 1; std::memcpy(s.data() + vec_offset(s, kDiscX), &n, 8); }, "engine state"},
      {"magic", [](std::string& s) { s[0] ^= 1; }, "engine magic"},
      {"time NaN", [&](std::string& s) { std::memcpy(s.data() + 8, &nan, 8); }, "time"},
      {"truncated", [](std::string& s) { s.resize(s.size() / 2); }, "truncated"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    std::string s = good;
    c.change(s);
    engine::Simulation b = make_engine();
    std::istringstream in(s);
    const std::string m = message_of([&] { b.load(in); });
    EXPECT_TRUE(contains(m, "engine state")) << m;
    EXPECT_TRUE(contains(m, c.needle)) << m;
    EXPECT_EQ(b.bodies().x.size(), 0u) << "a refused load leaves the engine unchanged";
  }
}

// ---- the whole run checkpoint ----
namespace {
nip::NipConfig small_config() {
  return nip::parse_nip_config(nip::preset_text("black"), "preset:black",
                                       {"geometry.window_x_min_m=-100e-6", "geometry.window_x_max_m=100e-6",
                                        "collision.stiffness_scale=0.01", "output.vtk=false", "magnet.dipole_dipole=true"});
}
// Advances to t, then sends body 0 out of the window and runs one inflow/outflow pass: the state
// then holds a removal event, a renumbered disc set and forces not yet re-evaluated.
void advance_and_remove(nip::NipRun& run, double t) {
  run.advance_to(t);
  run.sim().bodies().x[0] = run.config().x_max + 1e-3;
  run.exchange();
}
std::string run_checkpoint(double t) {
  nip::NipRun run(small_config());
  advance_and_remove(run, t);
  EXPECT_GE(run.removals().size(), 1u);
  return run.checkpoint();
}
}  // namespace

TEST(RunCheckpoint, IdenticalRunsWriteIdenticalBytesAndDamageIsRefusedNamingTheFile) {
  const std::string a = run_checkpoint(4e-6), b = run_checkpoint(4e-6);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b) << "two identical runs must write byte-identical checkpoints";
  nip::NipRun target(small_config());
  target.restore(a, "runs/x/checkpoint.bin");  // the undamaged file restores
  auto refused = [&](const std::string& blob, const char* needle) {
    const std::string m = message_of([&] { target.restore(blob, "runs/x/checkpoint.bin"); });
    EXPECT_TRUE(contains(m, "runs/x/checkpoint.bin: ")) << m;
    EXPECT_TRUE(contains(m, needle)) << m;
  };
  for (std::size_t cut : {std::size_t{0}, std::size_t{5}, std::size_t{31}, std::size_t{32}, a.size() / 3, a.size() - 1})
    refused(a.substr(0, cut), cut < 32 ? "not a nipdem checkpoint" : "truncated");
  refused(a + std::string(1, '\0'), "appended");
  refused(a + a, "appended");
  // >= 20 seeded random single-bit flips anywhere in the file, plus 4 in the header.
  Rng rng(2112);
  int flips = 0;
  for (int k = 0; k < 28; ++k) {
    std::string d = a;
    const std::size_t at = k < 4 ? static_cast<std::size_t>(rng.uniform(0, 32)) : static_cast<std::size_t>(rng.uniform(0, static_cast<double>(a.size())));
    const int bit = static_cast<int>(rng.uniform(0, 8));
    d[std::min(at, a.size() - 1)] ^= static_cast<char>(1 << std::min(bit, 7));
    SCOPED_TRACE("flip at byte " + std::to_string(at) + " bit " + std::to_string(bit));
    const std::string m = message_of([&] { target.restore(d, "runs/x/checkpoint.bin"); });
    EXPECT_TRUE(contains(m, "runs/x/checkpoint.bin: ")) << m;
    ++flips;
  }
  EXPECT_GE(flips, 20);
  // an older format is refused with a message saying so
  refused("NIPDEMRUN3" + a.substr(10), "older nipdem");
}

TEST(RunCheckpoint, HugeCountersAreRefusedWithoutOverflow) {
  // Found by fuzz_checkpoint (UBSan): removal counters near 2^62 overflowed their sum.
  std::string payload(io::open_checkpoint(run_checkpoint(2e-6), "x"));
  const std::size_t removed_at = 10 + 2 * 8 + 4 * 8 + 2 * 8;  // tag, keys, rng, inserted counters
  const std::int64_t huge = std::int64_t{1} << 62;
  for (int k = 0; k < 2; ++k) std::memcpy(payload.data() + removed_at + 8 * k, &huge, 8);
  nip::NipRun target(small_config());
  const std::string m = message_of([&] { target.restore(io::seal_checkpoint(payload), "x"); });
  EXPECT_TRUE(contains(m, "particle counter")) << m;
}

TEST(RunCheckpoint, ResealedRandomDamageNeverCrashes) {
  // Damage the checksum cannot see (a payload re-sealed after the change, as a buggy writer or a
  // crafted file would): each load either succeeds with a checked state or throws InputError.
  const std::string a = run_checkpoint(2e-6);
  const std::string payload(io::open_checkpoint(a, "x"));
  nip::NipRun target(small_config());
  Rng rng(77);
  int refused = 0;
  for (int k = 0; k < 300; ++k) {
    std::string p = payload;
    const auto at = static_cast<std::size_t>(rng.uniform(0, static_cast<double>(p.size())));
    p[std::min(at, p.size() - 1)] ^= static_cast<char>(1 << static_cast<int>(rng.uniform(0, 7.999)));
    try {
      target.restore(io::seal_checkpoint(p), "x");
    } catch (const InputError&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
  target.restore(a, "x");  // and a good one still restores afterwards
}

TEST(RunCheckpoint, ResumeRightAfterBodiesWereRemovedIsBitwiseIdentical) {
  // The checkpoint holds the list of the old numbering, the renumbering and "forces not valid":
  // the resumed run re-evaluates forces and carries contact history exactly as the original.
  nip::NipRun a(small_config());
  advance_and_remove(a, 4e-6);
  const std::string blob = a.checkpoint();
  nip::NipRun b(small_config());
  b.restore(blob, "x");
  const double t = 8e-6;
  a.advance_to(t);
  b.advance_to(t);
  const auto& ba = a.sim().bodies();
  const auto& bb = b.sim().bodies();
  ASSERT_EQ(ba.x.size(), bb.x.size());
  ASSERT_GT(ba.x.size(), 10u);
  for (std::size_t i = 0; i < ba.x.size(); ++i) {
    ASSERT_EQ(ba.x[i], bb.x[i]) << i;
    ASSERT_EQ(ba.vy[i], bb.vy[i]) << i;
    ASSERT_EQ(ba.omega[i], bb.omega[i]) << i;
  }
  EXPECT_EQ(a.checkpoint(), b.checkpoint());
}
