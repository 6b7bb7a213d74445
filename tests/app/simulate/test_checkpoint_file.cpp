// checkpoint.bin's identity and checksum (app/simulate/checkpoint_file.h, issue 30 item 1): every
// single flipped bit is an error, and a checkpoint of another scene, mesh, protocol or build is
// refused naming which. (The whole resume on the command line: Cli.ResumeNeverMixesRuns.)
#include <filesystem>
#include <fstream>
#include <functional>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/simulate/checkpoint_file.h"
#include "core/errors.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using pneufem::test::error_of;

const RunIdentity kId{"0000000000000001", "0000000000000002", "0000000000000003", "0000000000000004"};
const std::string kBody = std::string("state\0with\0zeros\n", 17) + "and more";

/// `text` in a file of the running test's own (ctest runs the tests in parallel processes).
fs::path write(const std::string& text) {
  const fs::path p = fs::temp_directory_path() /
                     ("pneufem_test_checkpoint_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + ".bin");
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

TEST(CheckpointFile, RoundTripsItsBody) {
  EXPECT_EQ(read_checkpoint_body(write(checkpoint_file_text(kId, kBody)), kId, "RUN"), kBody);
}

// Before, a flipped bit resumed silently; now every single-bit change anywhere in the file is an
// error (FNV-1a changes with any one byte).
TEST(CheckpointFile, EveryFlippedBitIsAnError) {
  const std::string text = checkpoint_file_text(kId, kBody);
  for (std::size_t i = 0; i < text.size(); ++i)
    for (int bit = 0; bit < 8; ++bit) {
      std::string bad = text;
      bad[i] = static_cast<char>(bad[i] ^ (1 << bit));
      const std::string e = error_of([&] { read_checkpoint_body(write(bad), kId, "RUN"); });
      ASSERT_NE(e, "(no error)") << "byte " << i << " bit " << bit;
    }
  const std::string cut = error_of([&] { read_checkpoint_body(write(text.substr(0, text.size() - 5)), kId, "RUN"); });
  EXPECT_THAT(cut, HasSubstr("damaged"));
  EXPECT_THAT(cut, HasSubstr("run it again: pneufem simulate RUN/scene.toml --out RUN"));
  EXPECT_THAT(error_of([&] { read_checkpoint_body(write("old format"), kId, "RUN"); }), HasSubstr("not a checkpoint"));
}

TEST(CheckpointFile, AnotherRunOrBuildIsRefusedNamingWhatDiffers) {
  const fs::path f = write(checkpoint_file_text(kId, kBody));
  RunIdentity other = kId;
  other.scene = "ffffffffffffffff";
  EXPECT_THAT(error_of([&] { read_checkpoint_body(f, other, "RUN"); }), HasSubstr("belongs to another run: its scene differs"));
  other = kId;
  other.mesh = "ffffffffffffffff";
  EXPECT_THAT(error_of([&] { read_checkpoint_body(f, other, "RUN"); }), HasSubstr("its mesh differs"));
  other = kId;
  other.protocol = "ffffffffffffffff";
  EXPECT_THAT(error_of([&] { read_checkpoint_body(f, other, "RUN"); }), HasSubstr("its load protocol differs"));
  other = kId;
  other.executable = "ffffffffffffffff";
  EXPECT_THAT(error_of([&] { read_checkpoint_body(f, other, "RUN"); }), HasSubstr("another build of pneufem"));
}

TEST(CheckpointFile, TheIdentityFollowsTheSceneAndTheProtocol) {
  const Scene s = Scene::load("");
  const Model m;
  LoadHistory load;
  const RunIdentity a = run_identity(s, m, load);
  EXPECT_EQ(run_identity(Scene::load(""), m, load).scene, a.scene);
  EXPECT_NE(run_identity(s.with({"load.hold_s=12.0"}), m, load).scene, a.scene);
  load.trials.push_back(TrialLoad{{0.0, 1.0}, {0.0, 5e3}, {1.0}, {}, {}, {}});
  EXPECT_NE(run_identity(s, m, load).protocol, a.protocol);
  EXPECT_EQ(run_identity(s, m, load).mesh, a.mesh);
  EXPECT_FALSE(a.executable.empty());
}

}  // namespace
}  // namespace pneufem
