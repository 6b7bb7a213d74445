#include "engine/path_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <numeric>
#include <string>
#include <utility>

#include "core/errors.h"
#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/nonlocal.h"
#include "engine/path_spline.h"
#include "engine/tet_element.h"

namespace pneufem {

namespace {

/// F at quadrature point q of element e (q = -1: volume-weighted mean of the element's points,
/// the centroid value for Tet10 since F is linear there).
Mat3 deformation_gradient(const Mesh& mesh, const ElementGeometry& geom, const Eigen::VectorXd& u, int e, int q) {
  const int* n = mesh.element(e);
  auto at = [&](int qq) {
    const double* g = geom.grad(e, qq);
    Mat3 F = Mat3::Identity();
    for (int a = 0; a < geom.npe; ++a) F += u.segment<3>(3 * n[a]) * Eigen::Map<const Eigen::RowVector3d>(g + 3 * a);
    return F;
  };
  if (q >= 0) return at(q);
  Mat3 F = Mat3::Zero();
  double wsum = 0.0;
  for (int qq = 0; qq < geom.nqp; ++qq) {
    F += geom.w(e, qq) * at(qq);
    wsum += geom.w(e, qq);
  }
  return F / wsum;
}

/// Material points grouped by material, so each group is one batched Material::evaluate.
struct Groups {
  std::vector<const Material*> material;
  std::vector<std::vector<int>> points;
  std::vector<std::size_t> state_offset;  ///< per group, into the run's state vector
  std::size_t state_size = 0;
};

Groups group_points(const Model& model, const std::vector<int>& pt_element) {
  Groups g;
  std::vector<int> group_of_part(model.parts.size(), -1);
  for (std::size_t i = 0; i < pt_element.size(); ++i) {
    const int part = model.element_part[pt_element[i]];
    if (group_of_part[part] < 0) {
      group_of_part[part] = static_cast<int>(g.material.size());
      g.material.push_back(model.parts[part].material.get());
      g.points.emplace_back();
    }
    g.points[group_of_part[part]].push_back(static_cast<int>(i));
  }
  for (std::size_t k = 0; k < g.material.size(); ++k) {
    g.state_offset.push_back(g.state_size);
    g.state_size += g.points[k].size() * static_cast<std::size_t>(g.material[k]->state_size());
  }
  return g;
}

/// One segment of the path for all material points: F at both samples and its theta-slopes.
/// Why cubic and not linear in theta: with F linear on each segment, F'(theta) jumps at every
/// sample, and so does G_model - G_ref of any model that is not the reference (a pressure jump of
/// (P_model - P_ref) : [F'] / V'). The equilibrium angle then sticks to samples or jumps past
/// them as the constants change, which made the calibration objective piecewise constant at the
/// 1 % level (0.4 deg at 45 kPa for a 0.05 % change of a Prony gamma on the default actuator,
/// 2026-11-26) and trapped the optimiser in the gamma-tau valley far from its minimum. The cubic
/// is the cubic spline through the samples (spline_slopes, engine/path_spline.h), so F' and F'' are continuous.
struct PathSegment {
  const Mat3 *F0, *F1, *M0, *M1;
  Hermite h;
  Mat3 F(int i, Mat3* dF) const { return h(F0[i], F1[i], M0[i], M1[i], dF); }
};

/// Segment k of a path with np points per sample, at a = (theta - theta_k) / dth.
PathSegment path_segment(const std::vector<Mat3>& F, const std::vector<Mat3>& dF, const std::vector<double>& theta,
                         std::size_t np, std::size_t k, double a) {
  const std::size_t o = k * np;
  return PathSegment{F.data() + o, F.data() + o + np, dF.data() + o, dF.data() + o + np, Hermite(a, theta[k + 1] - theta[k])};
}

/// Generalised force sum_points w P(F(theta)) : F'(theta) over the points of `g` on path segment
/// `seg`. Reads/writes the groups' history in state_old/state_new when given.
double generalised_force(const Groups& g, const PathSegment& seg, const std::vector<double>& weight,
                         const std::vector<int>& pt_element, const TimeStep& ts, const std::vector<double>* state_old,
                         std::vector<double>* state_new, std::vector<Mat3>& Fbuf, std::vector<Mat3>& dFbuf,
                         std::vector<PointResponse>& rbuf) {
  double G = 0.0;
  for (std::size_t gi = 0; gi < g.material.size(); ++gi) {
    const std::vector<int>& pts = g.points[gi];
    Fbuf.resize(pts.size());
    dFbuf.resize(pts.size());
    rbuf.resize(pts.size());
    for (std::size_t j = 0; j < pts.size(); ++j) Fbuf[j] = seg.F(pts[j], &dFbuf[j]);
    const std::size_t ss = static_cast<std::size_t>(g.material[gi]->state_size()) * pts.size();
    std::span<const double> so = state_old ? std::span<const double>(*state_old).subspan(g.state_offset[gi], ss)
                                           : std::span<const double>();
    std::span<double> sn = state_new ? std::span<double>(*state_new).subspan(g.state_offset[gi], ss) : std::span<double>();
    g.material[gi]->evaluate(Fbuf, ts, so, sn, rbuf, false);
    for (std::size_t j = 0; j < pts.size(); ++j) {
      const double c = weight[pts[j]] * (rbuf[j].P().cwiseProduct(dFbuf[j])).sum();
      if (!std::isfinite(c))
        throw PhysicsError("reduced model: non-finite stress in element " + std::to_string(pt_element[pts[j]] + 1) +
                               "; the material or its effects are out of their valid range",
                           pt_element[pts[j]], ts.time_s);
      G += c;
    }
  }
  return G;
}

void check_options(const PathModelOptions& o) {
  if (!(o.dp_Pa > 0.0) || !(o.p_top_Pa > o.dp_Pa) || o.max_points < 1 || !(o.max_dt_s > 0.0))
    throw InputError("path model: need 0 < dp_Pa < p_top_Pa, max_points >= 1 and max_dt_s > 0");
}

Eigen::Vector3d first_moment(const Eigen::VectorXd& mass, const Eigen::VectorXd& u) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (Eigen::Index a = 0; a < mass.size(); ++a) s += mass[a] * u.segment<3>(3 * a);
  return s;
}

}  // namespace

ElasticPathTrace trace_elastic_path(const Model& reference, const PathModelOptions& options) {
  check_options(options);
  const Assembler asmb(reference);
  if (asmb.state_size() != 0)
    throw InputError("path model: the reference model must be elastic (materials without history)");
  // The path ends at its first failed sample: a limit point only needs locating to within a
  // fraction of the sample spacing, not to the solver's default 1 Pa. Near the limit every failed
  // sub-increment costs max_iterations Newton iterations, and halving dp down to 1 Pa was half of
  // the trace's wall time on the hidden-effect test actuator (BENCHMARKS.md section 8).
  StaticOptions newton = options.newton;
  newton.min_increment_Pa = std::max(newton.min_increment_Pa, options.dp_Pa / 16.0);
  StaticSolver solver(asmb, newton);
  // Load control; ends quietly at a limit point.
  ElasticPathTrace tr;
  tr.p_Pa = {0.0};
  tr.u = {Eigen::VectorXd::Zero(reference.num_dofs())};
  double theta = 0.0;
  std::vector<double> state;
  for (double p = options.dp_Pa; p <= options.p_top_Pa + 1e-9; p += options.dp_Pa) {
    Eigen::VectorXd trial = tr.u.back();
    try {
      solver.advance(tr.p_Pa.back(), p, 0.0, 0.0, state, trial);
    } catch (const PhysicsError&) {
      break;  // limit point (or inversion) beyond this pressure: the path ends here
    }
    const double th = unwrap_deg(bending_angle(reference, trial).angle_deg, theta);
    if (!(th > theta)) break;  // the angle must increase along the path
    theta = th;
    tr.u.push_back(std::move(trial));
    tr.p_Pa.push_back(p);
  }
  if (tr.p_Pa.size() < 3)
    throw PhysicsError("path model: the elastic path could not be traced beyond " + std::to_string(tr.p_Pa.back()) +
                       " Pa; check the model with pneufem simulate first");
  return tr;
}

PathModel::PathModel(const Model& reference, const PathModelOptions& options)
    : PathModel(reference, options, trace_elastic_path(reference, options)) {}

PathModel::PathModel(const Model& reference, const PathModelOptions& options, const ElasticPathTrace& trace)
    : ref_(reference), opt_(options) {
  check_options(opt_);
  const Assembler asmb(reference);
  if (asmb.state_size() != 0)
    throw InputError("path model: the reference model must be elastic (materials without history)");
  take_trace(asmb, trace);
  choose_points(asmb, trace.u.back());
  precompute_path(asmb, trace.u);
}

void PathModel::take_trace(const Assembler& asmb, const ElasticPathTrace& trace) {
  const std::vector<Eigen::VectorXd>& us = trace.u;
  auto bad = [](const std::string& why) {
    return InputError("path model: the elastic path trace " + why +
                      " (a stored trace that is damaged or belongs to another model: delete it and trace again)");
  };
  if (us.size() != trace.p_Pa.size() || us.size() < 3) throw bad("has fewer than three samples or mismatched sizes");
  const Eigen::VectorXd& mass = asmb.lumped_mass();
  for (std::size_t k = 0; k < us.size(); ++k) {
    if (us[k].size() != ref_.num_dofs())
      throw bad("has " + std::to_string(us[k].size()) + " dof, the model " + std::to_string(ref_.num_dofs()));
    if (!us[k].allFinite() || !std::isfinite(trace.p_Pa[k])) throw bad("holds non-finite values");
    double th = 0.0;
    if (k == 0) {
      if (trace.p_Pa[0] != 0.0 || !us[0].isZero(0.0)) throw bad("does not start unloaded");
    } else {
      th = unwrap_deg(bending_angle(ref_, us[k]).angle_deg, theta_.back());
      if (!(th > theta_.back() && trace.p_Pa[k] > p_.back()))
        throw bad("is not increasing in pressure and angle at sample " + std::to_string(k));
    }
    theta_.push_back(th);
    p_.push_back(trace.p_Pa[k]);
    V_.push_back(asmb.cavity_volume(us[k]));
    S_.push_back(first_moment(mass, us[k]));
  }
}

void PathModel::choose_points(const Assembler& asmb, const Eigen::VectorXd& u_top) {
  const Mesh& mesh = ref_.mesh;
  const ElementGeometry& geom = asmb.geometry();
  const int ne = mesh.num_elements();
  if (static_cast<long>(ne) * geom.nqp <= opt_.max_points) {
    for (int e = 0; e < ne; ++e)
      for (int q = 0; q < geom.nqp; ++q) {
        pt_element_.push_back(e);
        pt_qp_.push_back(q);
        pt_weight_.push_back(geom.w(e, q));
      }
    return;
  }
  // Importance sample of elements: probability pi_e = (volume share + energy share at the path's
  // top) / 2; systematic sampling of n positions on the cumulative distribution; each pick keeps
  // every quadrature point of its element, with the Horvitz-Thompson weight w_eq / (n pi_e), so
  // sums over picks estimate volume integrals without bias, while the high-energy elements (where
  // damage lives) are densely covered. Every quadrature point, not the element centroid: the
  // interior walls bend, and the centroid (the element's mean strain) misses the bending strain
  // that varies through a wall one or two quadratic elements thick. History driven by it is then
  // underestimated — by a third of the creep near the default actuator's limit point with
  // viscoelasticity (2026-11-26: 4.4 deg instead of the FEM's 6.4 deg after a 16 s hold at
  // 45 kPa; 6.1 deg with every quadrature point), whatever the number of elements sampled.
  const int n = std::max(1, opt_.max_points / geom.nqp);
  std::vector<double> energy(ne);
  double vtot = 0.0, etot = 0.0;
  for (int e = 0; e < ne; ++e) {
    const Mat3 F = deformation_gradient(mesh, geom, u_top, e, -1);
    PointResponse r;
    std::vector<double> none;
    ref_.material_of(e).evaluate(std::span<const Mat3>(&F, 1), TimeStep{}, none, none, std::span<PointResponse>(&r, 1),
                                 false);
    energy[e] = std::max(0.0, r.psi()) * geom.volume[e];
    vtot += geom.volume[e];
    etot += energy[e];
  }
  double cum = 0.0;
  int next = 0;
  for (int e = 0; e < ne && next < n; ++e) {
    const double pi = 0.5 * geom.volume[e] / vtot + (etot > 0.0 ? 0.5 * energy[e] / etot : 0.5 * geom.volume[e] / vtot);
    cum += pi;
    while (next < n && (next + 0.5) / n < cum) {
      for (int q = 0; q < geom.nqp; ++q) {
        pt_element_.push_back(e);
        pt_qp_.push_back(q);
        pt_weight_.push_back(geom.w(e, q) / (n * pi));
      }
      ++next;
    }
  }
}

void PathModel::precompute_path(const Assembler& asmb, const std::vector<Eigen::VectorXd>& us) {
  const Mesh& mesh = ref_.mesh;
  const ElementGeometry& geom = asmb.geometry();
  const std::size_t np = pt_element_.size();
  F_.resize(np * theta_.size());
  for (std::size_t k = 0; k < theta_.size(); ++k)
    for (std::size_t i = 0; i < np; ++i) F_[k * np + i] = deformation_gradient(mesh, geom, us[k], pt_element_[i], pt_qp_[i]);
  // Slopes for the smooth path (PathSegment says why): of F per point, of V and of S.
  dF_.resize(F_.size());
  for (std::size_t i = 0; i < np; ++i) {
    const std::vector<Mat3> m = spline_slopes<Mat3>(theta_, [&](std::size_t k) { return F_[k * np + i]; });
    for (std::size_t k = 0; k < theta_.size(); ++k) dF_[k * np + i] = m[k];
  }
  dV_ = spline_slopes<double>(theta_, [&](std::size_t k) { return V_[k]; });
  dS_ = spline_slopes<Eigen::Vector3d>(theta_, [&](std::size_t k) { return S_[k]; });

  // The reference's equilibrium pressure between samples: a monotone cubic in theta (Fritsch-
  // Carlson slopes) rather than a chord. The chord made the elastic model's angle up to ~0.1°
  // (0.2 %) off its FEM curve between samples near the limit point, where p_el(theta) flattens;
  // diagnose compares at that level. Beyond the ends the residual stays linear (extrapolation).
  dp_dtheta_ = monotone_slopes(theta_, p_);

  // The reference's generalised force on a fine grid of each segment: the difference form
  // needs G_ref at every residual evaluation, and it never changes.
  const Groups gr = group_points(ref_, pt_element_);
  std::vector<Mat3> Fbuf, dFbuf;
  std::vector<PointResponse> rbuf;
  Gref_.resize((theta_.size() - 1) * (kRefSub + 1));
  for (std::size_t k = 0; k + 1 < theta_.size(); ++k)
    for (int j = 0; j <= kRefSub; ++j)
      Gref_[k * (kRefSub + 1) + j] = generalised_force(gr, path_segment(F_, dF_, theta_, np, k, static_cast<double>(j) / kRefSub),
                                                       pt_weight_, pt_element_, TimeStep{}, nullptr, nullptr, Fbuf, dFbuf, rbuf);
}

int PathModel::segment(double theta) const { return path_segment_index(theta_, theta); }

/// One run of `model` along the path: the history of its material points (committed in
/// state_old_, trial in state_new_), the non-local drivers, the equilibrium residual and the
/// scalar root finder that places the model on the path at each physical step.
class PathModel::Run {
 public:
  Run(const PathModel& path, const Model& model)
      : pm_(path), model_(model), np_(path.pt_element_.size()), gm_(group_points(model, path.pt_element_)),
        gr_(group_points(path.ref_, path.pt_element_)), state_old_(gm_.state_size), state_new_(gm_.state_size),
        pt_slot_(np_, {-1, 0}) {
    for (std::size_t k = 0; k < gm_.material.size(); ++k) {
      const int ss = gm_.material[k]->state_size();
      for (std::size_t j = 0; j < gm_.points[k].size(); ++j)
        gm_.material[k]->init_state(std::span<double>(state_new_).subspan(gm_.state_offset[k] + j * ss, ss));
    }
    state_old_ = state_new_;
    build_nonlocal();
    const double p_scale = std::max(1.0, pm_.p_.back());
    tol_Pa_ = 1e-7 * p_scale;
    tol_theta_ = 1e-9 * std::max(1.0, pm_.theta_.back());
  }

  /// Equilibrium at (t, p) after a physical step dt from the committed state, committed: a
  /// bracketed secant (Illinois) on the scalar residual.
  void solve(double t, double dt, double p);
  double theta() const { return theta_; }
  const PathRunStats& stats() const { return st_; }

 private:
  /// Non-local drivers (engine/nonlocal.h) over the reduced model's own quadrature points, with
  /// their (importance-sampling) weights as volumes; the same protocol as the FEM's
  /// Assembler::update_nonlocal, after every committed state.
  void build_nonlocal();
  void update_nonlocal(double theta);
  /// Equilibrium residual in pressure units (Pa): p_el + (G_model - G_ref - g.S') / V' - p.
  double residual(double theta, double p, const TimeStep& ts);
  /// A trial point leaving the traced path stops at its end first (see solve).
  double keep_on_path(double from, double to) const {
    if (from > pm_.theta_.front() && to < pm_.theta_.front()) return pm_.theta_.front();
    if (from < pm_.theta_.back() && to > pm_.theta_.back()) return pm_.theta_.back();
    return to;
  }
  /// Secant extrapolation from (x0, f0), (x1, f1) until the root is bracketed or the secant has
  /// converged from one side; throws PhysicsError when it finds none.
  void bracket_root(double& x0, double& f0, double& x1, double& f1, double slope, double t, double p,
                    const TimeStep& ts);
  /// Illinois false position inside the bracket [x0, x1].
  void illinois(double& x0, double& f0, double& x1, double& f1, double p, const TimeStep& ts);

  const PathModel& pm_;
  const Model& model_;
  const std::size_t np_;
  const Groups gm_;  ///< the model's points by material
  const Groups gr_;  ///< the reference's, for extrapolation beyond the path
  std::vector<double> state_old_, state_new_;
  std::vector<std::pair<int, std::size_t>> pt_slot_;  ///< (group, index within it) per point
  std::unique_ptr<NonlocalAverage> nonlocal_;
  std::vector<Mat3> Fbuf_, dFbuf_;
  std::vector<PointResponse> rbuf_;
  PathRunStats st_;
  double tol_Pa_ = 0.0, tol_theta_ = 0.0;
  double theta_ = 0.0;  ///< the committed angle
  double ratio_ = 1.0;  ///< the softening ratio seen at the last step (the secant's first slope)
};

void PathModel::Run::build_nonlocal() {
  for (std::size_t k = 0; k < gm_.material.size(); ++k)
    for (std::size_t j = 0; j < gm_.points[k].size(); ++j) pt_slot_[gm_.points[k][j]] = {static_cast<int>(k), j};
  std::map<std::pair<std::string, double>, int> group_of;
  std::vector<double> radius;
  std::vector<NonlocalAverage::Point> pts(np_);
  const Mesh& mesh = pm_.ref_.mesh;
  const auto rule = tet_rule(mesh.type);
  std::array<double, 10> N{};
  std::array<double, 30> dN{};
  for (std::size_t i = 0; i < np_; ++i) {
    const Material::NonlocalSpec spec = gm_.material[pt_slot_[i].first]->nonlocal();
    if (!(spec.radius_m > 0.0)) continue;
    const auto [it, added] = group_of.emplace(std::make_pair(spec.kind, spec.radius_m), static_cast<int>(radius.size()));
    if (added) radius.push_back(spec.radius_m);
    const int e = pm_.pt_element_[i], npe = mesh.npe();
    const int q = pm_.pt_qp_[i];
    tet_shape(mesh.type, rule[q].xi, rule[q].eta, rule[q].zeta, N.data(), dN.data());
    for (int a = 0; a < npe; ++a) pts[i].X += N[a] * mesh.X[mesh.element(e)[a]];
    pts[i].volume_m3 = pm_.pt_weight_[i];
    pts[i].group = it->second;
  }
  if (!radius.empty()) nonlocal_ = std::make_unique<NonlocalAverage>(pts, radius);
}

void PathModel::Run::update_nonlocal(double theta) {
  if (!nonlocal_) return;
  const int k = pm_.segment(theta);
  const double a = (theta - pm_.theta_[k]) / (pm_.theta_[k + 1] - pm_.theta_[k]);
  const PathSegment seg = path_segment(pm_.F_, pm_.dF_, pm_.theta_, np_, static_cast<std::size_t>(k), a);
  std::vector<double> X(np_, 0.0), Xbar(np_, 0.0);
  Mat3 dF;
  auto point_state = [&](std::size_t i) {
    const auto [gi, j] = pt_slot_[i];
    const std::size_t ss = static_cast<std::size_t>(gm_.material[gi]->state_size());
    return std::span<double>(state_old_).subspan(gm_.state_offset[gi] + j * ss, ss);
  };
  for (std::size_t i = 0; i < np_; ++i)
    X[i] = gm_.material[pt_slot_[i].first]->nonlocal_driver(seg.F(static_cast<int>(i), &dF), point_state(i));
  nonlocal_->average(X, Xbar);
  for (std::size_t i = 0; i < np_; ++i)
    gm_.material[pt_slot_[i].first]->set_nonlocal_driver(point_state(i), X[i], Xbar[i]);
}

double PathModel::Run::residual(double theta, double p, const TimeStep& ts) {
  ++st_.evaluations;
  const std::vector<double>& th = pm_.theta_;
  const int k = pm_.segment(theta);
  const double dth = th[k + 1] - th[k], a = (theta - th[k]) / dth;
  const bool inside = a >= 0.0 && a <= 1.0;
  const PathSegment seg = path_segment(pm_.F_, pm_.dF_, th, np_, static_cast<std::size_t>(k), a);
  // p_el with the monotone slopes (beyond the ends the end slopes are the end chords);
  // V'(theta) and S'(theta) of the same spline as F (a chord slope would jump at the samples
  // just as F' did); the chord if the cubic's slope is not positive (not seen).
  double dp = 0.0, dV = 0.0;
  const double p_el = seg.h(pm_.p_[k], pm_.p_[k + 1], pm_.dp_dtheta_[k], pm_.dp_dtheta_[k + 1], &dp);
  seg.h(pm_.V_[k], pm_.V_[k + 1], pm_.dV_[k], pm_.dV_[k + 1], &dV);
  if (!(dV > 0.0)) dV = (pm_.V_[k + 1] - pm_.V_[k]) / dth;
  Eigen::Vector3d dS;
  seg.h(pm_.S_[k], pm_.S_[k + 1], pm_.dS_[k], pm_.dS_[k + 1], &dS);
  const double gS = model_.gravity_m_s2.dot(dS);
  const double Gm =
      generalised_force(gm_, seg, pm_.pt_weight_, pm_.pt_element_, ts, &state_old_, &state_new_, Fbuf_, dFbuf_, rbuf_);
  double Gr = 0.0;
  if (inside) {  // cached reference force, linear between kRefSub sub-points
    const double x = a * kRefSub;
    const int j = std::min(static_cast<int>(x), kRefSub - 1);
    const double* c = pm_.Gref_.data() + static_cast<std::size_t>(k) * (kRefSub + 1);
    Gr = c[j] + (x - j) * (c[j + 1] - c[j]);
  } else {
    Gr = generalised_force(gr_, seg, pm_.pt_weight_, pm_.pt_element_, TimeStep{}, nullptr, nullptr, Fbuf_, dFbuf_, rbuf_);
  }
  const double dG = Gm - Gr;
  return p_el + (dG - gS) / dV - p;
}

void PathModel::Run::bracket_root(double& x0, double& f0, double& x1, double& f1, double slope, double t, double p,
                                  const TimeStep& ts) {
  int it = 0;
  const double span = pm_.theta_.back() - pm_.theta_.front();
  while (f0 * f1 > 0.0 && std::abs(f1) > tol_Pa_) {
    if (++it > 60 || std::abs(x1) > 20.0 * span + 360.0)
      throw PhysicsError("reduced model: no equilibrium on the elastic path at t = " + std::to_string(t) +
                             " s, p = " + std::to_string(p) + " Pa (the softened model may have passed its limit "
                             "point); use the full FEM (pneufem simulate) to check this case",
                         -1, t);
    double s = (f1 - f0) / (x1 - x0);
    if (!(s > 0.0)) s = slope;
    double x2 = x1 - f1 / s;
    const double max_step = 4.0 * std::abs(x1 - x0) + 1.0;
    x2 = keep_on_path(x1, std::clamp(x2, x1 - max_step, x1 + max_step));
    x0 = x1, f0 = f1;
    x1 = x2, f1 = residual(x1, p, ts);
  }
}

void PathModel::Run::illinois(double& x0, double& f0, double& x1, double& f1, double p, const TimeStep& ts) {
  int side = 0;
  for (int it = 0; it < 100 && std::abs(f1) > tol_Pa_ && std::abs(x1 - x0) > tol_theta_; ++it) {
    const double x2 = (x0 * f1 - x1 * f0) / (f1 - f0);
    const double f2 = residual(x2, p, ts);
    if (f2 * f1 < 0.0) {
      x0 = x1, f0 = f1;
      side = 0;
    } else if (++side >= 2) {
      f0 *= 0.5;
    }
    x1 = x2, f1 = f2;
  }
}

void PathModel::Run::solve(double t, double dt, double p) {
  const TimeStep ts{t, dt};
  const std::vector<double>& th = pm_.theta_;
  double x0 = theta_, f0 = residual(x0, p, ts);
  if (std::abs(f0) > tol_Pa_) {
    const int k = pm_.segment(x0);
    // Initial slope: the elastic path's, times the softening ratio seen at the last step.
    const double slope = ratio_ * (pm_.p_[k + 1] - pm_.p_[k]) / (th[k + 1] - th[k]);
    // A trial point leaving the traced path stops at its end first (keep_on_path): inside the path
    // the residual is the model's, outside it an extrapolation, and a secant step that overshoots
    // (strongly softened or recovering states, a vent from the top level to 0) must not find a
    // spurious root out there. At theta = 0 the residual is -p (no stress in the undeformed
    // state), so a drop in pressure is always bracketed inside the path.
    double x1 = keep_on_path(x0, x0 - f0 / slope), f1 = residual(x1, p, ts);
    // Extrapolate until the root is bracketed, or the secant has converged from one side (it
    // often does on a smooth residual; without this exit it would stall and report no root).
    bracket_root(x0, f0, x1, f1, slope, t, p, ts);
    illinois(x0, f0, x1, f1, p, ts);
    if (x1 != x0) {
      const int kk = pm_.segment(x1);
      const double s_el = (pm_.p_[kk + 1] - pm_.p_[kk]) / (th[kk + 1] - th[kk]);
      const double s_now = (f1 - f0) / (x1 - x0);
      if (s_now > 0.0 && std::isfinite(s_now)) ratio_ = std::clamp(s_now / s_el, 0.05, 20.0);
    }
    x0 = x1;
    residual(x0, p, ts);  // leaves the root's trial state in state_new_
  }
  theta_ = x0;
  if (theta_ > th.back() || theta_ < th.front()) st_.beyond_path = true;
  state_old_.swap(state_new_);  // commit
  update_nonlocal(theta_);
  ++st_.steps;
}

std::vector<double> PathModel::run(const Model& model, const PathLoad& load, PathRunStats* stats) const {
  if (model.mesh.num_elements() != ref_.mesh.num_elements() || model.mesh.num_nodes() != ref_.mesh.num_nodes())
    throw InputError("path model: the model's mesh differs from the reference mesh the path was traced on");
  if (load.t_s.size() != load.p_Pa.size() || load.t_s.empty())
    throw InputError("path model: the load needs as many times as pressures, at least one");
  for (std::size_t i = 1; i < load.t_s.size(); ++i)
    if (!(load.t_s[i] > load.t_s[i - 1])) throw InputError("path model: load times must increase strictly");

  Run run(*this, model);
  std::vector<double> out;
  out.reserve(load.t_s.size());
  run.solve(load.t_s[0], 0.0, load.p_Pa[0]);
  out.push_back(run.theta());
  for (std::size_t i = 1; i < load.t_s.size(); ++i) {
    const double t0 = load.t_s[i - 1], t1 = load.t_s[i];
    const int m = std::max(1, static_cast<int>(std::ceil((t1 - t0) / opt_.max_dt_s - 1e-9)));
    for (int j = 1; j <= m; ++j) {
      const double f = static_cast<double>(j) / m;
      const double t = t0 + f * (t1 - t0);
      run.solve(t, (t1 - t0) / m, load.p_Pa[i - 1] + f * (load.p_Pa[i] - load.p_Pa[i - 1]));
    }
    out.push_back(run.theta());
  }
  if (stats) *stats = run.stats();
  return out;
}

}  // namespace pneufem
