// `pneufem mesh model.stl --out mesh.vtu|.inp`: a closed surface meshed with the default scene
// (mesh.source = "stl"), its quality printed; bad surfaces are exit code 2 with the repair named.
#include <filesystem>

#include <gtest/gtest.h>

#include "scenes/pneunet.h"
#include "tests/app/cli_helpers.h"
#include "tests/scenes/stl/test_shapes.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;

TEST(MeshStl, WritesVtuAndInpWithTheQualityReport) {
  const fs::path d = test::fresh_dir("mesh_stl");
  fs::create_directories(d);
  PneuNetParams p;
  p.chambers = 3;
  write_stl((d / "three.stl").string(), test::pneunet_surface(p), 1e-3);
  const test::CliResult vtu = test::run_cli("mesh " + (d / "three.stl").string() + " --out " + (d / "m.vtu").string());
  ASSERT_EQ(vtu.code, 0) << vtu.out;
  EXPECT_NE(vtu.out.find("dihedral angles"), std::string::npos) << vtu.out;
  EXPECT_NE(vtu.out.find("C3D10 elements"), std::string::npos) << vtu.out;
  EXPECT_TRUE(fs::exists(d / "m.vtu"));
  const test::CliResult inp =
      test::run_cli("mesh " + (d / "three.stl").string() + " --out " + (d / "m.inp").string() + " --set mesh.h_mm=3.0");
  ASSERT_EQ(inp.code, 0) << inp.out;
  const std::string deck = test::slurp(d / "m.inp");
  EXPECT_NE(deck.find("*ELEMENT, TYPE=C3D10"), std::string::npos);
  EXPECT_NE(deck.find("CAVITY"), std::string::npos);
}

TEST(MeshStl, AnOpenSurfaceIsExitCodeTwoWithTheRepair) {
  const fs::path d = test::fresh_dir("mesh_stl_open");
  fs::create_directories(d);
  PneuNetParams p;
  p.chambers = 2;
  TriSurface s = test::pneunet_surface(p);
  s.F.resize(s.F.size() - 2);
  write_stl((d / "open.stl").string(), s, 1e-3);
  const test::CliResult r = test::run_cli("mesh " + (d / "open.stl").string() + " --out " + (d / "m.vtu").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("open edge(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Close Holes"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace pneufem
