#include "fit/fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/QR>
#include <nlopt.hpp>

#include "core/errors.h"
#include "core/number_text.h"
#include "fit/nnls_small.h"

namespace pneufem::fit {

namespace detail {

Nnls nnls_small(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  const int n = static_cast<int>(A.cols());
  Nnls best{Eigen::VectorXd::Zero(n), b.squaredNorm()};
  for (int mask = 1; mask < (1 << n); ++mask) {
    std::vector<int> cols;
    for (int k = 0; k < n; ++k)
      if (mask & (1 << k)) cols.push_back(k);
    Eigen::MatrixXd S(A.rows(), static_cast<Eigen::Index>(cols.size()));
    for (std::size_t k = 0; k < cols.size(); ++k) S.col(static_cast<Eigen::Index>(k)) = A.col(cols[k]);
    const Eigen::VectorXd xs = S.colPivHouseholderQr().solve(b);
    if (!xs.allFinite() || (xs.array() <= 0.0).any()) continue;
    const double rss = (S * xs - b).squaredNorm();
    if (rss < best.rss) {
      best.rss = rss;
      best.x.setZero();
      for (std::size_t k = 0; k < cols.size(); ++k) best.x[cols[k]] = xs[static_cast<Eigen::Index>(k)];
    }
  }
  return best;
}

}  // namespace detail

namespace {

using detail::nnls_small;
using detail::Nnls;


/// The files of `tests`, for messages: "uniaxial a.csv (12 points), planar b.csv (8 points)".
std::string describe(const std::vector<TestCurve>& tests) {
  std::string s;
  for (std::size_t t = 0; t < tests.size(); ++t) {
    int n = 0;
    for (const TestPoint& p : tests[t].points) n += p.stretch != 1.0;
    s += (t ? ", " : "") + std::string(mode_name(tests[t].mode)) + " " + tests[t].source + " (" +
         std::to_string(n) + " points)";
  }
  return s;
}

/// The weighted least-squares rows of every point: A.row(i) = w_i dP_i/dc, b_i = w_i P_i.
struct Rows {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
};

Rows weighted_rows(const std::vector<TestCurve>& tests, Law law, const std::vector<double>& alpha, Weighting w) {
  std::size_t n = 0;
  for (const TestCurve& t : tests) n += t.points.size();
  const int p = modulus_count(law, static_cast<int>(alpha.size()));
  Rows r{Eigen::MatrixXd(static_cast<Eigen::Index>(n), p), Eigen::VectorXd(static_cast<Eigen::Index>(n))};
  Eigen::Index i = 0;
  for (const TestCurve& t : tests) {
    const std::vector<double> wt = point_weights(t, w);
    for (std::size_t j = 0; j < t.points.size(); ++j, ++i) {
      r.A.row(i) = wt[j] * nominal_stress_basis(law, alpha, t.mode, t.points[j].stretch).transpose();
      r.b[i] = wt[j] * t.points[j].P_Pa;
    }
  }
  return r;
}

void check_constants(const std::vector<TestCurve>& tests, const Constants& k) {
  try {
    make_law_material(k, 1.0);  // only the law's checks of its constants matter here
  } catch (const InputError& e) {
    throw InputError("the fitted " + std::string(law_name(k.law)) + " constants are not a usable material (" +
                     e.what() + "); data: " + describe(tests) +
                     ". The data do not pin down a positive small-strain stiffness: add points at small strain, "
                     "fit a narrower range (--max-strain), or use a law with fewer constants (neo_hookean, "
                     "mooney_rivlin)");
  }
}

FitResult fit_linear(const std::vector<TestCurve>& tests, const FitOptions& o) {
  const Rows r = weighted_rows(tests, o.law, {}, o.weighting);
  const int p = static_cast<int>(r.A.cols());
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(r.A);
  if (qr.rank() < p)
    throw InputError("the points of " + describe(tests) + " do not determine the " + std::to_string(p) + " constants of " +
                     law_name(o.law) + " (they are too few distinct stretches); add points at other strains or use a "
                     "law with fewer constants");
  const Eigen::VectorXd c = qr.solve(r.b);
  FitResult f;
  f.constants = Constants{o.law, std::vector<double>(c.data(), c.data() + p), {}};
  check_constants(tests, f.constants);
  f.evaluations = 1;
  const double rss = (r.A * c - r.b).squaredNorm();
  const Eigen::Index n = r.A.rows();
  if (n > p) {  // covariance s^2 (A^T A)^-1 = s^2 P R^-1 R^-T P^T from the QR, without forming A^T A
    const Eigen::MatrixXd R = qr.matrixR().topLeftCorner(p, p).template triangularView<Eigen::Upper>();
    const Eigen::MatrixXd Rinv = R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p, p));
    const Eigen::MatrixXd cov = qr.colsPermutation() * (Rinv * Rinv.transpose()) * qr.colsPermutation().transpose();
    const double s2 = rss / static_cast<double>(n - p);
    for (int k = 0; k < p; ++k) f.std_error.push_back(std::sqrt(s2 * cov(k, k)));
  }
  return f;
}

/// The N-combinations (sorted, distinct) of the start values of the exponents.
std::vector<std::vector<double>> alpha_starts(int N) {
  static const std::vector<double> kValues = {-4.0, -2.0, -1.0, 0.5, 1.0, 2.0, 3.0, 5.0, 8.0};
  std::vector<std::vector<double>> out;
  std::vector<int> idx(N);
  for (int i = 0; i < N; ++i) idx[i] = i;
  const int m = static_cast<int>(kValues.size());
  while (true) {
    std::vector<double> a;
    for (int i : idx) a.push_back(kValues[i]);
    out.push_back(a);
    int i = N - 1;
    while (i >= 0 && idx[i] == m - N + i) --i;
    if (i < 0) break;
    ++idx[i];
    for (int j = i + 1; j < N; ++j) idx[j] = idx[j - 1] + 1;
  }
  return out;
}

struct OgdenObjective {
  const std::vector<TestCurve>* tests;
  Weighting weighting;
  int evaluations = 0;
  double operator()(const std::vector<double>& alpha) {
    ++evaluations;
    const Rows r = weighted_rows(*tests, Law::ogden, alpha, weighting);
    const double rss = nnls_small(r.A, r.b).rss;
    return std::isfinite(rss) ? rss : std::numeric_limits<double>::max();
  }
};

double ogden_thunk(const std::vector<double>& x, std::vector<double>&, void* data) {
  return (*static_cast<OgdenObjective*>(data))(x);
}

FitResult fit_ogden(const std::vector<TestCurve>& tests, const FitOptions& o) {
  const int N = o.ogden_terms;
  OgdenObjective f{&tests, o.weighting};
  double best_value = std::numeric_limits<double>::infinity();
  std::vector<double> best_alpha;
  nlopt::result best_result = nlopt::FAILURE;
  for (std::vector<double> x : alpha_starts(N)) {
    nlopt::opt opt(nlopt::LN_BOBYQA, static_cast<unsigned>(N));
    opt.set_lower_bounds(std::vector<double>(N, -o.alpha_bound));
    opt.set_upper_bounds(std::vector<double>(N, o.alpha_bound));
    opt.set_min_objective(ogden_thunk, &f);
    opt.set_xtol_rel(1e-10);
    opt.set_ftol_rel(1e-14);
    opt.set_initial_step(std::vector<double>(N, 0.25));
    opt.set_maxeval(o.max_evaluations);
    double value = 0.0;
    nlopt::result res = nlopt::FAILURE;
    try {
      res = opt.optimize(x, value);
    } catch (const nlopt::roundoff_limited&) {  // converged as far as round-off allows: x is the best point
      res = nlopt::FTOL_REACHED;
      value = f(x);
    } catch (const std::exception&) {
      continue;  // a failed start; the others decide
    }
    if (value < best_value) {
      best_value = value;
      best_alpha = x;
      best_result = res;
    }
  }
  if (best_alpha.empty() || best_result == nlopt::MAXEVAL_REACHED || best_result == nlopt::MAXTIME_REACHED)
    throw InputError("the ogden" + std::to_string(N) + " fit of " + describe(tests) + " did not converge within " +
                     std::to_string(o.max_evaluations) + " evaluations per start (" + std::to_string(f.evaluations) +
                     " in all); raise --max-evaluations, or use fewer terms");

  const Rows r = weighted_rows(tests, Law::ogden, best_alpha, o.weighting);
  const Nnls mu = nnls_small(r.A, r.b);
  FitResult out;
  out.evaluations = f.evaluations;
  std::vector<std::pair<double, double>> terms;  // (alpha, mu), kept when mu > 0
  for (int i = 0; i < N; ++i) {
    if (mu.x[i] > 0.0) terms.emplace_back(best_alpha[i], mu.x[i]);
    else
      out.notes.push_back("term with alpha = " + short_num(best_alpha[i]) +
                          " came out with mu = 0 and is dropped: the data need fewer terms");
    if (std::abs(best_alpha[i]) >= 0.999 * o.alpha_bound)
      out.notes.push_back("alpha = " + short_num(best_alpha[i]) + " is at its bound " + short_num(o.alpha_bound) +
                          ": the fit wants a stiffer exponent than allowed; check the data's largest strains");
  }
  if (terms.empty())
    throw InputError("the ogden fit of " + describe(tests) + " found no term with mu > 0: the data do not rise "
                     "with strain as a rubber does; check the stress column and its sign");
  std::sort(terms.begin(), terms.end());
  out.constants.law = Law::ogden;
  for (const auto& [a, m] : terms) {
    out.constants.alpha.push_back(a);
    out.constants.c.push_back(m);
  }
  check_constants(tests, out.constants);
  return out;
}

}  // namespace

int constant_count(const FitOptions& o) {
  return o.law == Law::ogden ? 2 * o.ogden_terms : modulus_count(o.law, o.ogden_terms);
}

std::vector<double> point_weights(const TestCurve& t, Weighting w) {
  if (w == Weighting::absolute) return std::vector<double>(t.points.size(), 1e-6);  // 1/MPa
  double largest = 0.0;
  for (const TestPoint& p : t.points) largest = std::max(largest, std::abs(p.P_Pa));
  const double floor = 0.01 * largest;
  std::vector<double> out;
  for (const TestPoint& p : t.points) out.push_back(1.0 / std::max({std::abs(p.P_Pa), floor, 1e-300}));
  return out;
}

std::vector<TestFit> evaluate_fit(const std::vector<TestCurve>& tests, const Constants& k, Weighting w) {
  std::vector<TestFit> out;
  for (const TestCurve& t : tests) {
    TestFit f;
    f.weight = point_weights(t, w);
    const std::vector<double> rel = point_weights(t, Weighting::relative);
    double mean = 0.0;
    for (const TestPoint& p : t.points) mean += p.P_Pa / static_cast<double>(t.points.size());
    double ss_res = 0.0, ss_tot = 0.0, rel2 = 0.0;
    for (std::size_t j = 0; j < t.points.size(); ++j) {
      const TestPoint& p = t.points[j];
      const double Pm = nominal_stress(k, t.mode, p.stretch);
      f.model_P_Pa.push_back(Pm);
      ss_res += (Pm - p.P_Pa) * (Pm - p.P_Pa);
      ss_tot += (p.P_Pa - mean) * (p.P_Pa - mean);
      rel2 += std::pow((Pm - p.P_Pa) * rel[j], 2);
      f.objective += std::pow((Pm - p.P_Pa) * f.weight[j], 2);
    }
    f.r2 = ss_tot > 0.0 ? 1.0 - ss_res / ss_tot : std::numeric_limits<double>::quiet_NaN();
    f.rms_relative = t.points.empty() ? 0.0 : std::sqrt(rel2 / static_cast<double>(t.points.size()));
    out.push_back(f);
  }
  return out;
}

double objective(const std::vector<TestCurve>& tests, const Constants& k, Weighting w) {
  double e = 0.0;
  for (const TestFit& f : evaluate_fit(tests, k, w)) e += f.objective;
  return e;
}

FitResult fit_hyperelastic(const std::vector<TestCurve>& tests, const FitOptions& o) {
  if (o.law == Law::ogden && (o.ogden_terms < 1 || o.ogden_terms > 3))
    throw InputError("ogden fits have 1 to 3 terms (ogden1, ogden2, ogden3), got " + std::to_string(o.ogden_terms));
  if (tests.empty()) throw InputError("no test data to fit");
  int n = 0;
  for (const TestCurve& t : tests)
    for (const TestPoint& p : t.points) n += p.stretch != 1.0;
  const int need = constant_count(o);
  if (n < need)
    throw InputError(std::string(law_name(o.law)) + (o.law == Law::ogden ? std::to_string(o.ogden_terms) : "") +
                     " has " + std::to_string(need) + " constants and needs at least as many points away from the "
                     "origin; the data have " + std::to_string(n) + ": " + describe(tests) +
                     ". Add points, or use a law with fewer constants (neo_hookean 1, mooney_rivlin 2, yeoh 3, "
                     "ogdenN 2N)");
  FitResult f = o.law == Law::ogden ? fit_ogden(tests, o) : fit_linear(tests, o);
  f.tests = evaluate_fit(tests, f.constants, o.weighting);
  f.objective = 0.0;
  for (const TestFit& t : f.tests) f.objective += t.objective;
  return f;
}

}  // namespace pneufem::fit
