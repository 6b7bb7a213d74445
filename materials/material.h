#pragma once
// The constitutive interface the engine evaluates at every quadrature point.
//
// A Material is immutable once built (parameters validated in the constructor) and is
// evaluated as a pure function of the deformation gradient F and an explicit per-point
// history state: the committed state is read, the trial state is written, and the
// integrator alone decides when a trial becomes committed (FEBio's pattern). Purely
// elastic laws have state_size() == 0.
//
// Responses are split into an isochoric ("iso") and a volumetric ("vol") part because the
// inelastic effects of damage/ (Mullins, fatigue, viscoelasticity) act on the isochoric part
// only, as Abaqus and FEBio define them; laws that are not split (St Venant-Kirchhoff) put
// everything in "iso" and report is_split() == false.
//
// Units: SI (Pa for stresses and energy densities J/m^3, s for time).
#include <algorithm>
#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "materials/tensor.h"

namespace pneufem {

/// Response of a material at one point. P = P_iso + P_vol (first Piola-Kirchhoff, Pa),
/// psi = psi_iso + psi_vol (Helmholtz energy per reference volume, J/m^3), A = dP/dF (Pa).
struct PointResponse {
  double psi_iso = 0.0;
  double psi_vol = 0.0;
  Mat3 P_iso = Mat3::Zero();
  Mat3 P_vol = Mat3::Zero();
  // Tangents are left uninitialised (81 doubles each) unless a tangent is requested: zeroing
  // them on every force-only evaluation cost more than the stress itself.
  Mat9 A_iso;  ///< only valid when a tangent was requested
  Mat9 A_vol;

  double psi() const { return psi_iso + psi_vol; }
  Mat3 P() const { return P_iso + P_vol; }
  Mat9 A() const { return A_iso + A_vol; }
};

/// Deformation gradients and force-only responses of up to kLanes points in structure-of-arrays
/// layout: component k = i + 3J (tensor.h) of point l is at [k][l]. A law's loops over the lanes
/// then have the same body for every lane, which the compiler vectorises at the baseline ISA (2
/// doubles per SSE2 instruction); elementwise IEEE operations round as the scalar ones do. The
/// engine's force kernel evaluates its elements this way (BENCHMARKS §4).
struct StressBatch {
  static constexpr int kLanes = 8;
  int n = 0;  ///< points in use; lanes n..kLanes-1 are padding (see pad())
  double F[9][kLanes];
  double psi_iso[kLanes], psi_vol[kLanes];
  double P_iso[9][kLanes], P_vol[9][kLanes];

  void set_F(int l, const Mat3& Fl) {
    for (int k = 0; k < 9; ++k) F[k][l] = Fl(k);
  }
  Mat3 F_of(int l) const {
    Mat3 Fl;
    for (int k = 0; k < 9; ++k) Fl(k) = F[k][l];
    return Fl;
  }
  /// Stores a point's force-only response (psi and P halves) in lane l.
  void set_response(int l, const PointResponse& r) {
    psi_iso[l] = r.psi_iso;
    psi_vol[l] = r.psi_vol;
    for (int k = 0; k < 9; ++k) {
      P_iso[k][l] = r.P_iso(k);
      P_vol[k][l] = r.P_vol(k);
    }
  }
  /// Copies point 0's F into the unused lanes, so that a law may compute every lane.
  void pad() {
    for (int k = 0; k < 9; ++k)
      for (int l = n; l < kLanes; ++l) F[k][l] = F[k][0];
  }
};

/// Physical-time information for rate-dependent laws. A purely elastic evaluation
/// (e.g. the pseudo-time iterations of a static solve) keeps dt_s = 0 semantics: laws
/// then return the state reached at the end of the increment dt_s.
struct TimeStep {
  double time_s = 0.0;  ///< physical time at the end of the increment
  double dt_s = 0.0;    ///< physical increment since the committed state (>= 0)
};

/// Scalar outputs a material can report per point for visualisation (damage etc.).
struct PointFields {
  double damage = 0.0;          ///< isochoric softening 1 - (stiffness fraction), in [0, 1)
  double W_max = 0.0;           ///< peak isochoric energy density seen so far (J/m^3)
  double viscous_strain = 0.0;  ///< norm of the viscous (overstress) strain measure
  double fatigue_damage = 0.0;  ///< the rate-dependent (time-driven) part of `damage`
  /// True once a failure criterion of the law is met (fatigue: damage >= d_fail). The point keeps a
  /// small residual stiffness, so the solution stays finite; the driver decides what to do with it.
  bool failed = false;
};

class Material {
 public:
  virtual ~Material() = default;

  /// Short name, e.g. "yeoh", "mullins(yeoh)".
  virtual std::string name() const = 0;

  /// Number of doubles of history per quadrature point (0 for elastic laws).
  virtual int state_size() const { return 0; }
  /// Writes the virgin state into `state` (size state_size()).
  virtual void init_state(std::span<double> state) const { (void)state; }

  /// Evaluates n = F.size() points. `state_old` and `state_new` hold n * state_size()
  /// doubles (either may be empty when state_size() == 0). When `tangent` is false the
  /// A_* members of `out` are left untouched.
  virtual void evaluate(std::span<const Mat3> F, const TimeStep& step,
                        std::span<const double> state_old, std::span<double> state_new,
                        std::span<PointResponse> out, bool tangent) const = 0;

  /// Force-only evaluation of the batch's points 0..b.n-1: psi and P exactly (bit for bit) as
  /// evaluate(..., tangent = false) returns them, same state conventions (b.n * state_size() doubles).
  /// F is padded (StressBatch::pad), so an override may compute all lanes; what it writes to the
  /// padding lanes is ignored. The default converts to evaluate's layout, point by point; laws
  /// override it with structure-of-arrays arithmetic (a linear tet's force is then ~2x faster).
  virtual void stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
                      std::span<double> state_new) const;

  /// Visualisation fields from a (committed) state of one point.
  virtual PointFields fields(std::span<const double> state) const {
    (void)state;
    return {};
  }

  /// Small-strain moduli at F = I (Pa): used for stable-step estimates and scaling.
  virtual double initial_shear_modulus() const = 0;
  virtual double initial_bulk_modulus() const = 0;
  /// True when the response is split as P_iso (isochoric) + P_vol (volumetric).
  virtual bool is_split() const { return true; }
  /// True when d(psi_iso)/dF = P_iso at a fixed committed state (the reported isochoric energy is a
  /// potential of the isochoric stress). The energy-driven effects (damage/mullins.h,
  /// damage/fatigue.h) need it of the law they wrap; a law whose history moves within the increment
  /// (fatigue) or whose stress has an overstress part (viscoelastic) says false.
  virtual bool isochoric_energy_is_potential() const { return true; }

  /// Non-local regularisation (engine/nonlocal.h). A law whose history is driven by a local quantity
  /// (the fatigue law's stretch or energy) may have it averaged over a ball of radius radius_m > 0
  /// around each point; only points of the same `kind` and radius are averaged together. After every
  /// committed state the engine reads each point's driver (nonlocal_driver, from the committed state
  /// and its F) and hands back the average (set_nonlocal_driver), which the law keeps in its state
  /// for the following increments. Decorators forward the three calls to their base (with the base's
  /// slice of the state). Default: local (radius 0), and the calls do nothing.
  /// Linear-drive history (engine/quasi_static.h, solver.time_control = "drive"). A law whose history
  /// update over a physical step is EXACT when a quantity D of its state varies linearly in time over
  /// the step (the exponential Prony update and the elastic stress S0, damage/viscoelastic.h) says
  /// here how the update's local error depends on D's curvature: over a step of length h at a
  /// point where |D''| = c,
  ///   e(h) = c sum_i a_i tau_i^2 G(h / tau_i)      (in units of PointFields::viscous_strain),
  /// with G(x) = (x/2 - 1)(1 - exp(-x)) + x exp(-x) (engine/history_step.h, linear_drive_error).
  /// terms = 0 (the default): the law has no such history. `recovery` bounds D's total change while
  /// the history relaxes fully at fixed load, in units of the point's viscous strain (the step
  /// control's first step after a kink, where no curvature is known yet).
  struct LinearDrive {
    int terms = 0;
    std::array<double, 3> a{}, tau_s{};
    double recovery = 1.0;
    bool operator==(const LinearDrive&) const = default;
  };
  virtual LinearDrive linear_drive() const { return {}; }
  /// D at a committed state of one point: 6 doubles, a symmetric tensor as (11, 22, 33, sqrt2 23,
  /// sqrt2 13, sqrt2 12), so that its Euclidean norm is the tensor's Frobenius norm; in units of
  /// viscous_strain. Only called when linear_drive().terms > 0. Decorators forward both calls to
  /// their base (with the base's slice of the state); at most one layer of a stack has a drive.
  virtual void linear_drive_value(std::span<const double> state, std::span<double> out) const {
    (void)state;
    (void)out;
  }

  /// Cycle jumping (engine/cycle_jump.h; Cojocaru & Karlsson 2006, Abaqus "Low-cycle fatigue
  /// analysis using the direct cyclic approach"). `before` and `after` are one point's committed
  /// states at the ends of two consecutive load cycles; jump_cycles writes into `out` the state N
  /// cycles after `after`, each history variable extrapolated linearly in a measure that grows
  /// about linearly per cycle (fatigue: the integrity's s^(1-n); Mullins: the peak energy), and
  /// variables set by the last part of a cycle (the Prony branches, fixed by the rest) copied from
  /// `after`. jump_error says by how much two states of a point differ in what the extrapolated
  /// variables do to the stress, as the largest change of the isochoric stiffness fraction they
  /// can cause (dimensionless); the engine compares a one-cycle prediction with a computed cycle.
  /// A law says it can do this with jumps_cycles(); the default can for laws without history and
  /// refuses for others, so a law that does not know how its history extrapolates never jumps.
  /// Decorators extrapolate their own part and forward the rest (their base's slice) to the base.
  virtual bool jumps_cycles() const { return state_size() == 0; }
  virtual void jump_cycles(std::span<const double> before, std::span<const double> after, double cycles,
                           std::span<double> out) const {
    (void)before;
    (void)cycles;
    std::copy(after.begin(), after.end(), out.begin());
  }
  virtual double jump_error(std::span<const double> predicted, std::span<const double> computed) const {
    (void)predicted;
    (void)computed;
    return 0.0;
  }

  struct NonlocalSpec {
    double radius_m = 0.0;
    std::string kind;
  };
  virtual NonlocalSpec nonlocal() const { return {}; }
  virtual double nonlocal_driver(const Mat3& F, std::span<const double> state) const {
    (void)F;
    (void)state;
    return 0.0;
  }
  virtual void set_nonlocal_driver(std::span<double> state, double local, double average) const {
    (void)state;
    (void)local;
    (void)average;
  }
};

using MaterialPtr = std::shared_ptr<const Material>;

}  // namespace pneufem
