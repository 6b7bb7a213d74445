// The angle's frame of a deck (scenes/angle_frame.cpp): taken from the mesh when the scene leaves the
// angle keys at their defaults, checked when it sets them, the same bend in any orientation, the free
// end face found without a tip set, and the rig angle in the deck's own frame.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "engine/assembly.h"
#include "engine/quasi_static.h"
#include "scenes/build_model.h"
#include "tests/scenes/inp/deck_files.h"

namespace pneufem {
namespace {

using namespace pneufem::test;

// A deck oriented otherwise than the built-in actuator (here along x instead of y). Left at their
// defaults, the angle keys are taken from the mesh (the clamped face's outward normal, the side of the
// stiff layer), with a note each; set by the user, they are checked: a fixed normal in a wrong plane is
// refused with the normal to use, a bend direction pointing away from the fabric (it only flips the
// sign) is a warning.
TEST_F(InpFiles, TheAngleFrameComesFromTheMeshUnlessSetAndIsCheckedWhenSet) {
  Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0", "mesh.half=false"}));
  for (Eigen::Vector3d& x : mesh.X) x = Eigen::Vector3d(x.y(), -x.x(), x.z());  // y -> x: along x now
  std::ostringstream os;
  write_inp_mesh(os, mesh, 1e-3);
  const std::string path = write("along_x.inp", os.str());
  auto scene = [&](std::vector<std::string> extra) {
    extra.insert(extra.begin(), {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\""});
    return Scene::load("", extra);
  };
  const auto detected = build_model(scene({}));
  EXPECT_NEAR((detected->model.angle.fixed_normal_out - Eigen::Vector3d(-1.0, 0.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((detected->model.angle.bend_direction - Eigen::Vector3d(0.0, 0.0, -1.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(count_containing(detected->warnings, "angle.fixed_normal taken from the mesh: [-1.000, 0.000, 0.000]"), 1);
  // The default bend direction already points to the fabric: kept, no note.
  EXPECT_EQ(count_containing(detected->warnings, "angle.bend_direction"), 0);
  try {
    build_model(scene({"angle.fixed_normal=[0.0, -1.0, 0.0]"}));  // the built-in's normal, set on purpose
    ADD_FAILURE() << "a fixed normal in a wrong plane was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("angle.fixed_normal"), std::string::npos) << what;
    EXPECT_NE(what.find("outward normal is [-1.000, 0.000, 0.000]: set angle.fixed_normal = [-1.000, 0.000, 0.000]"),
              std::string::npos) << what;
  }
  const auto ok = build_model(scene({"angle.fixed_normal=[-1.0, 0.0, 0.0]"}));
  EXPECT_EQ(count_containing(ok->warnings, "angle."), 0);
  const auto flipped = build_model(scene({"angle.fixed_normal=[-1.0, 0.0, 0.0]", "angle.bend_direction=[0.0, 0.0, 1.0]"}));
  EXPECT_EQ(count_containing(flipped->warnings, "points away from the inextensible layer"), 1);
  EXPECT_EQ(count_containing(flipped->warnings, "set angle.bend_direction = [0.000, 0.000, -1.000]"), 1);
  // The built-in actuator with its own defaults: neither a note nor a warning.
  EXPECT_EQ(count_containing(build_model(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0"}))->warnings, "angle"), 0);
  // A rig angle hangs the deck in its own frame: phi = 0 along the actuator away from the clamp
  // (+x here), 90 deg towards the fabric (-z); it cannot be combined with a gravity vector.
  auto g_at = [&](const std::string& phi) { return build_model(scene({"gravity.rig_angle_deg=" + phi}))->model.gravity_m_s2; };
  EXPECT_NEAR((g_at("0.0") - Eigen::Vector3d(9.81, 0.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((g_at("90.0") - Eigen::Vector3d(0.0, 0.0, -9.81)).norm(), 0.0, 1e-12);
  EXPECT_EQ(build_model(scene({}))->model.gravity_m_s2, Eigen::Vector3d::Zero());  // -1: off
  for (const auto& [sets, hint] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"gravity.rig_angle_deg=200.0"}, "allowed: >= -360 and <= 180"},  // the scene's checked read (scenes/key_limits.cpp)
           {{"gravity.rig_angle_deg=10.0", "gravity.g_m_s2=[0.0, 0.0, -9.81]"}, "both give gravity"}}) {
    try {
      build_model(scene(sets));
      ADD_FAILURE() << hint;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("gravity.rig_angle_deg"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(hint), std::string::npos) << e.what();
    }
  }
}

// The same actuator as a deck in any orientation (a rotation about a skew axis: no coordinate axis
// along it) bends by the same angle with no angle keys at all: the frame is the mesh's. Both runs
// solve the same discrete equations in rotated coordinates to solver.rel_tol = 1e-8 of the force
// scale, so the angles agree far inside 1e-6 of the angle (round-off and the Newton tolerance only);
// the rotated deck with the built-in's frame forced on it would be refused (checked above).
TEST_F(InpFiles, ADeckInAnyOrientationBendsAsTheBuiltInWithoutAngleKeys) {
  Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0", "mesh.half=false"}));
  auto deck_of = [&](const Eigen::Matrix3d& R, const std::string& name) {
    Mesh m = mesh;
    for (Eigen::Vector3d& x : m.X) x = R * x;
    std::ostringstream os;
    write_inp_mesh(os, m, 1e-3);
    return write(name, os.str());
  };
  auto angle_at_10kPa = [](const std::string& deck, std::vector<std::string>* warnings) {
    const auto bm = build_model(Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + deck + "\"", "load.max_kPa=10.0",
                                                 "load.trials=1", "output.vtu=\"none\""}));
    if (warnings) *warnings = bm->warnings;
    const Assembler A(bm->model);
    QuasiStaticRun run(A, bm->solver.quasi_static);
    double last = 0.0;
    run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { last = r.angle_deg; });
    return last;
  };
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  std::vector<std::string> notes;
  const double upright = angle_at_10kPa(deck_of(Eigen::Matrix3d::Identity(), "upright.inp"), nullptr);
  const double tilted = angle_at_10kPa(deck_of(R, "tilted.inp"), &notes);
  EXPECT_GT(upright, 0.2);  // a real bend (0.39 deg for two chambers at 10 kPa), positive towards the fabric
  EXPECT_NEAR(tilted, upright, 1e-6 * upright);
  EXPECT_EQ(count_containing(notes, "angle.fixed_normal taken from the mesh"), 1);
  EXPECT_EQ(count_containing(notes, "angle.bend_direction taken from the mesh"), 1);
}

// A deck without the tip node set (and the scene leaving mesh.tip_set at its default): the free end
// face is found from the mesh (the boundary nodes farthest from the clamped face), with a note, and
// is exactly the built-in mesher's TIP set; a tip set named by the user must exist.
TEST_F(InpFiles, WithoutATipSetTheFreeEndFaceIsFoundFromTheMesh) {
  Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0", "mesh.half=false"}));
  const std::vector<int> tip = mesh.node_sets.at("TIP");
  mesh.node_sets.erase("TIP");
  for (Eigen::Vector3d& x : mesh.X) x = Eigen::Vector3d(x.y(), -x.x(), x.z());  // along x: no help from the defaults
  std::ostringstream os;
  write_inp_mesh(os, mesh, 1e-3);
  const std::string path = write("no_tip.inp", os.str());
  const auto bm = build_model(Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\""}));
  EXPECT_EQ(bm->model.angle.tip_nodes, tip);
  EXPECT_EQ(count_containing(bm->warnings, "mesh.tip_set: the deck has no node set 'TIP'; the free end face was taken from the mesh ("
                                           + std::to_string(tip.size()) + " boundary nodes at "), 1);
  try {
    build_model(Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\"", "mesh.tip_set=\"END\""}));
    ADD_FAILURE() << "a missing tip set named by the user was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("node set 'END' not found in the mesh"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pneufem
