#include "fit/inelastic.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include <nlopt.hpp>

#include "core/errors.h"
#include "core/number_text.h"
#include "fit/nnls_small.h"

namespace pneufem::fit {

namespace {

std::string files_of(const std::vector<TestCurve>& tests) {
  std::string s;
  for (const TestCurve& t : tests) s += (s.empty() ? "" : ", ") + t.source;
  return s;
}

/// Runs BOBYQA from every start within [lo, hi]; the best point and whether its run converged.
struct Search {
  std::vector<double> x;
  double value = std::numeric_limits<double>::infinity();
  bool converged = false;
  int evaluations = 0;
};

struct Objective {
  std::function<double(const std::vector<double>&)> f;
  int evaluations = 0;
};

double thunk(const std::vector<double>& x, std::vector<double>&, void* data) {
  Objective& o = *static_cast<Objective*>(data);
  ++o.evaluations;
  const double v = o.f(x);
  return std::isfinite(v) ? v : std::numeric_limits<double>::max();
}

Search bobyqa(const std::function<double(const std::vector<double>&)>& f, const std::vector<std::vector<double>>& starts,
              const std::vector<double>& lo, const std::vector<double>& hi, int max_evaluations) {
  Objective obj{f};
  Search best;
  for (std::vector<double> x : starts) {
    nlopt::opt opt(nlopt::LN_BOBYQA, static_cast<unsigned>(x.size()));
    opt.set_lower_bounds(lo);
    opt.set_upper_bounds(hi);
    opt.set_min_objective(thunk, &obj);
    opt.set_xtol_rel(1e-10);
    opt.set_ftol_rel(1e-14);
    opt.set_maxeval(max_evaluations);
    double value = 0.0;
    nlopt::result res = nlopt::FAILURE;
    try {
      res = opt.optimize(x, value);
    } catch (const nlopt::roundoff_limited&) {
      res = nlopt::FTOL_REACHED;
      value = f(x);
    } catch (const std::exception&) {
      continue;
    }
    if (value < best.value) {
      best.value = value;
      best.x = x;
      best.converged = res != nlopt::MAXEVAL_REACHED && res != nlopt::MAXTIME_REACHED;
    }
  }
  best.evaluations = obj.evaluations;
  return best;
}

double r_squared(const std::vector<double>& data, const std::vector<double>& model) {
  double mean = 0.0;
  for (double d : data) mean += d / static_cast<double>(data.size());
  double res = 0.0, tot = 0.0;
  for (std::size_t i = 0; i < data.size(); ++i) {
    res += (model[i] - data[i]) * (model[i] - data[i]);
    tot += (data[i] - mean) * (data[i] - mean);
  }
  return tot > 0.0 ? 1.0 - res / tot : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

TestCurve primary_loading(const TestCurve& t) {
  TestCurve p{t.mode, t.source, {}};
  double peak = 0.0;
  for (const TestPoint& q : t.points)
    if (q.stretch >= peak) {
      p.points.push_back(q);
      peak = q.stretch;
    }
  return p;
}

std::vector<double> mullins_stress(const TestCurve& t, const Constants& base, const MullinsParams& p) {
  std::vector<double> out;
  double W_max = 0.0;
  for (const TestPoint& q : t.points) {
    const double W = strain_energy(base, mode_stretches(t.mode, q.stretch));
    W_max = std::max(W_max, W);
    out.push_back(ogden_roxburgh(W, W_max, p).eta * nominal_stress(base, t.mode, q.stretch));
  }
  return out;
}

MullinsFit fit_mullins(const std::vector<TestCurve>& tests, const Constants& base, Weighting w, int max_evaluations) {
  MullinsFit out;
  double W_ref = 0.0;
  for (const TestCurve& t : tests) {
    out.unloading_points += static_cast<int>(t.points.size() - primary_loading(t).points.size());
    for (const TestPoint& q : t.points) W_ref = std::max(W_ref, strain_energy(base, mode_stretches(t.mode, q.stretch)));
  }
  if (out.unloading_points < 3)
    throw InputError("the Mullins fit needs unloading or reloading points below an earlier peak stretch (at least 3; "
                     "r, m and beta are fixed by them), and " + files_of(tests) + " ha" +
                     (tests.size() > 1 ? "ve " : "s ") + std::to_string(out.unloading_points) +
                     ": give loading-unloading cycles in time order");
  std::vector<std::vector<double>> weights;
  for (const TestCurve& t : tests) weights.push_back(point_weights(t, w));
  const auto params = [&](const std::vector<double>& x) {
    return MullinsParams{1.0 + std::exp(x[0]), x[1] * W_ref, x[2]};
  };
  const auto E = [&](const std::vector<double>& x) {
    const MullinsParams p = params(x);
    double e = 0.0;
    for (std::size_t t = 0; t < tests.size(); ++t) {
      const std::vector<double> P = mullins_stress(tests[t], base, p);
      for (std::size_t j = 0; j < P.size(); ++j) e += std::pow((P[j] - tests[t].points[j].P_Pa) * weights[t][j], 2);
    }
    return e;
  };
  std::vector<std::vector<double>> starts;
  for (double r : {1.5, 3.0})
    for (double m : {0.1, 0.5})
      for (double beta : {0.0, 0.5}) starts.push_back({std::log(r - 1.0), m, beta});
  const Search s = bobyqa(E, starts, {std::log(1e-3), 1e-6, 0.0}, {std::log(100.0), 10.0, 10.0}, max_evaluations);
  if (s.x.empty() || !s.converged)
    throw InputError("the Mullins fit of " + files_of(tests) + " did not converge within " +
                     std::to_string(max_evaluations) + " evaluations per start; raise --max-evaluations");
  out.params = params(s.x);
  out.objective = s.value;
  out.evaluations = s.evaluations;
  for (const TestCurve& t : tests) {
    out.model_P_Pa.push_back(mullins_stress(t, base, out.params));
    std::vector<double> data;
    for (const TestPoint& q : t.points) data.push_back(q.P_Pa);
    out.r2.push_back(r_squared(data, out.model_P_Pa.back()));
  }
  return out;
}

double prony_relaxation(const std::vector<double>& g, const std::vector<double>& tau_s, double t) {
  double v = 1.0;
  for (std::size_t i = 0; i < g.size(); ++i) v -= g[i] * -std::expm1(-t / tau_s[i]);
  return v;
}

PronyFit fit_prony(const RelaxationCurve& c, int terms, int max_evaluations) {
  if (terms < 1 || terms > 3) throw InputError("1 to 3 Prony terms can be fitted, got " + std::to_string(terms));
  if (static_cast<int>(c.points.size()) < 2 * terms)
    throw InputError(c.source + ": " + std::to_string(terms) + " Prony term(s) have " + std::to_string(2 * terms) +
                     " constants and need at least as many points; the file has " + std::to_string(c.points.size()));
  double t_min = std::numeric_limits<double>::infinity(), t_max = 0.0, g_first = 0.0, g_last = 0.0;
  for (const RelaxationPoint& p : c.points)
    if (p.t_s > 0.0) t_min = std::min(t_min, p.t_s), t_max = std::max(t_max, p.t_s);
  g_first = c.points.front().g;
  g_last = c.points.back().g;
  if (!(t_max > t_min) || !(g_last < g_first))
    throw InputError(c.source + ": the normalised stress does not fall over time (" + short_num(g_first) + " at line " +
                     std::to_string(c.points.front().line) + ", " + short_num(g_last) + " at line " +
                     std::to_string(c.points.back().line) +
                     "): no relaxation to fit. Give a held step: time since the step and the stress");
  const Eigen::Index n = static_cast<Eigen::Index>(c.points.size());
  Eigen::VectorXd b(n);  // 1 - g_R = sum g_i (1 - exp(-t/tau_i))
  for (Eigen::Index k = 0; k < n; ++k) b[k] = 1.0 - c.points[static_cast<std::size_t>(k)].g;
  const auto rows = [&](const std::vector<double>& ln_tau) {
    Eigen::MatrixXd A(n, static_cast<Eigen::Index>(ln_tau.size()));
    for (Eigen::Index k = 0; k < n; ++k)
      for (std::size_t i = 0; i < ln_tau.size(); ++i)
        A(k, static_cast<Eigen::Index>(i)) = -std::expm1(-c.points[static_cast<std::size_t>(k)].t_s / std::exp(ln_tau[i]));
    return A;
  };
  const auto E = [&](const std::vector<double>& ln_tau) { return detail::nnls_small(rows(ln_tau), b).rss; };
  const double lo = std::log(t_min / 10.0), hi = std::log(10.0 * t_max);
  std::vector<std::vector<double>> starts;  // terms spread over the decades, shifted three ways
  for (double shift : {0.25, 0.5, 0.75}) {
    std::vector<double> x;
    for (int i = 0; i < terms; ++i) x.push_back(lo + (hi - lo) * (i + shift) / terms);
    starts.push_back(x);
  }
  const Search s = bobyqa(E, starts, std::vector<double>(terms, lo), std::vector<double>(terms, hi), max_evaluations);
  if (s.x.empty() || !s.converged)
    throw InputError(c.source + ": the Prony fit did not converge within " + std::to_string(max_evaluations) +
                     " evaluations per start; raise --max-evaluations or use fewer terms");
  const detail::Nnls g = detail::nnls_small(rows(s.x), b);
  PronyFit f;
  f.evaluations = s.evaluations;
  std::vector<std::pair<double, double>> kept;  // (tau, g)
  for (int i = 0; i < terms; ++i) {
    if (g.x[i] > 0.0) kept.emplace_back(std::exp(s.x[i]), g.x[i]);
    else f.notes.push_back(c.source + ": Prony term with tau = " + short_num(std::exp(s.x[i])) +
                           " s came out with g = 0 and is dropped: the data need fewer terms");
    if (std::abs(s.x[i] - lo) < 1e-6 || std::abs(s.x[i] - hi) < 1e-6)
      f.notes.push_back(c.source + ": tau = " + short_num(std::exp(s.x[i])) +
                        " s is at the edge of what the data's time span can tell (t_min/10 or 10 t_max)");
  }
  if (kept.empty()) throw InputError(c.source + ": no Prony term with g > 0 fits: the data do not relax");
  std::sort(kept.begin(), kept.end());
  double sum = 0.0;
  for (const auto& [tau, gi] : kept) {
    f.tau_s.push_back(tau);
    f.g.push_back(gi);
    sum += gi;
  }
  if (!(sum < 1.0))
    throw InputError(c.source + ": the fitted Prony terms sum to g = " + short_num(sum) +
                     " >= 1: the stress relaxes to nothing (no long-term modulus), which a rubber does not; check "
                     "that the stress column is normalised by the stress right after the step, not by a later value");
  std::vector<double> data;
  for (const RelaxationPoint& p : c.points) {
    f.model.push_back(prony_relaxation(f.g, f.tau_s, p.t_s));
    data.push_back(p.g);
  }
  f.objective = g.rss;
  f.r2 = r_squared(data, f.model);
  return f;
}

}  // namespace pneufem::fit
