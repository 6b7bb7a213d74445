// The cache directory of app/simulate/result_cache.h: exact round trip, recomputation of damaged entries,
// one computation per key, keys that tell models apart. (Diagnose's use of it is tested in
// tests/app/diagnose/test_command.cpp, DiagnoseCache.)
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <string>
#include <thread>
#include <vector>
#include <atomic>
#include <chrono>

#include <gtest/gtest.h>

#include "app/simulate/result_cache.h"
#include "core/errors.h"
#include "scenes/build_model.h"

namespace fs = std::filesystem;

namespace pneufem {
namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / name;
  fs::remove_all(d);
  return d;
}

// Every bit comes back: subnormals, signed zero, infinities, the extremes (a trace that came back
// rounded would give a different diagnosis than the run that stored it).
TEST(ResultCache, StoresEveryBitAndComputesOnce) {
  const fs::path dir = fresh_dir("pneufem_result_cache_bits");
  const std::vector<double> v = {0.0, -0.0, 1.0 / 3.0, std::numeric_limits<double>::denorm_min(),
                                 std::numeric_limits<double>::max(), -std::numeric_limits<double>::infinity(), 1e-300};
  int calls = 0;
  auto compute = [&] {
    ++calls;
    return v;
  };
  std::string src;
  EXPECT_EQ(cached_doubles(dir.string(), "t", "k1", compute, &src), v);
  EXPECT_EQ(src, "computed");
  const std::vector<double> back = cached_doubles(dir.string(), "t", "k1", compute, &src);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(src, "cache " + (dir / "t_k1.bin").string());
  ASSERT_EQ(back.size(), v.size());
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(std::signbit(back[i]), std::signbit(v[i])) << i;
  EXPECT_EQ(back, v);
  cached_doubles(dir.string(), "t", "k2", compute);  // another key: computed again
  EXPECT_EQ(calls, 2);
  fs::remove_all(dir);
}

// Two runs asking for one entry at once: one computes, the other waits for it and reads it.
TEST(ResultCache, ConcurrentRequestsComputeOnce) {
  const fs::path dir = fresh_dir("pneufem_result_cache_race");
  std::atomic<int> calls{0};
  auto compute = [&] {
    ++calls;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    return std::vector<double>{2.5, 3.5};
  };
  std::vector<double> a, b;
  std::thread t1([&] { a = cached_doubles(dir.string(), "t", "k", compute); });
  std::thread t2([&] { b = cached_doubles(dir.string(), "t", "k", compute); });
  t1.join();
  t2.join();
  EXPECT_EQ(calls.load(), 1);
  EXPECT_EQ(a, (std::vector<double>{2.5, 3.5}));
  EXPECT_EQ(b, a);
  fs::remove_all(dir);
}

// A truncated file, a flipped byte and a foreign file are all recomputed and replaced, with the
// source saying so; the replaced entry is then read.
TEST(ResultCache, RecomputesADamagedEntry) {
  const fs::path dir = fresh_dir("pneufem_result_cache_damage");
  std::vector<double> v(100);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::sin(static_cast<double>(i));
  int calls = 0;
  auto compute = [&] {
    ++calls;
    return v;
  };
  const std::string file = (dir / "t_k.bin").string();
  cached_doubles(dir.string(), "t", "k", compute);
  auto damage = [&](const std::function<void(std::string&)>& f) {
    std::ifstream in(file, std::ios::binary);
    std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    in.close();
    f(b);
    std::ofstream(file, std::ios::binary | std::ios::trunc) << b;
  };
  const std::vector<std::function<void(std::string&)>> damages = {
      [](std::string& b) { b.resize(b.size() / 2); },
      [](std::string& b) { b[b.size() / 2] = static_cast<char>(b[b.size() / 2] ^ 0x10); },
      [](std::string& b) { b = "trial,time_s,angle_deg\n1,0,0\n"; }};
  for (std::size_t d = 0; d < damages.size(); ++d) {
    damage(damages[d]);
    std::string src;
    EXPECT_EQ(cached_doubles(dir.string(), "t", "k", compute, &src), v) << d;
    EXPECT_EQ(src, "recomputed (" + file + " was damaged)") << d;
    EXPECT_EQ(calls, static_cast<int>(d) + 2);
    cached_doubles(dir.string(), "t", "k", compute, &src);
    EXPECT_EQ(src, "cache " + file) << d;
  }
  fs::remove_all(dir);
}

TEST(ResultCache, AnUnusableDirectoryIsAnInputError) {
  const fs::path file = fresh_dir("pneufem_result_cache_file");
  std::ofstream(file) << "a file, not a directory\n";
  try {
    cached_doubles(file.string(), "t", "k", [] { return std::vector<double>{1.0}; });
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--cache " + file.string()), std::string::npos) << e.what();
  }
  fs::remove(file);
}

// The model key changes with the scene and with the mesh a scene builds, and not otherwise.
TEST(ResultCache, ModelKeysTellModelsApart) {
  auto key = [](const std::vector<std::string>& sets) {
    const Scene s = Scene::load("", sets);
    Fnv1a h;
    hash_model(h, s, build_model(s)->model);
    return h.hex();
  };
  const std::vector<std::string> base = {"geometry.chambers=2", "mesh.h_mm=8"};
  std::vector<std::string> softer = base, finer = base;
  softer.push_back("materials.silicone.stiffness_scale=0.9");
  finer.back() = "mesh.h_mm=7";
  EXPECT_EQ(key(base), key(base));
  EXPECT_NE(key(base), key(softer));
  EXPECT_NE(key(base), key(finer));
  EXPECT_EQ(executable_fingerprint().size(), 16u);
  EXPECT_EQ(executable_fingerprint(), executable_fingerprint());
}

}  // namespace
}  // namespace pneufem
