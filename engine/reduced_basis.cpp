// The reduced basis's mesh fingerprint and its storage with exact bits (engine/reduced_basis.h).
#include "engine/reduced_basis.h"

#include <cmath>
#include <cstdint>

#include "core/errors.h"

namespace pneufem {

double mesh_fingerprint(const Mesh& mesh) {
  std::uint64_t h = 0xcbf29ce484222325ULL;  // FNV-1a over the bytes
  auto mix = [&](const void* p, std::size_t n) {
    const unsigned char* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 0x100000001b3ULL;
  };
  for (const auto& x : mesh.X) mix(x.data(), 3 * sizeof(double));
  for (int e = 0; e < mesh.num_elements(); ++e) mix(mesh.element(e), static_cast<std::size_t>(mesh.npe()) * sizeof(int));
  return static_cast<double>(h >> 12);
}

// ------------------------------------------------------------------ serialisation
namespace {
constexpr double kMagic = 7.261126e6;  // format tag of ReducedBasis::to_doubles
constexpr double kVersion = 5.0;

struct Writer {
  std::vector<double> d;
  void num(double x) { d.push_back(x); }
  void vec(const std::vector<double>& v) {
    num(static_cast<double>(v.size()));
    d.insert(d.end(), v.begin(), v.end());
  }
  void mat(const Eigen::MatrixXd& m) {
    num(static_cast<double>(m.rows()));
    num(static_cast<double>(m.cols()));
    d.insert(d.end(), m.data(), m.data() + m.size());
  }
};

struct Reader {
  const std::vector<double>& d;
  std::size_t i = 0;
  double num() {
    if (i >= d.size()) throw InputError("reduced model: stored basis is truncated");
    return d[i++];
  }
  std::size_t count() {
    const double x = num();
    if (!(x >= 0.0) || x > 1e10 || x != std::floor(x)) throw InputError("reduced model: stored basis is damaged");
    return static_cast<std::size_t>(x);
  }
  std::vector<double> vec() {
    const std::size_t n = count();
    if (i + n > d.size()) throw InputError("reduced model: stored basis is truncated");
    std::vector<double> v(d.begin() + static_cast<std::ptrdiff_t>(i), d.begin() + static_cast<std::ptrdiff_t>(i + n));
    i += n;
    return v;
  }
  Eigen::MatrixXd mat() {
    const std::size_t r = count(), c = count();
    if (i + r * c > d.size()) throw InputError("reduced model: stored basis is truncated");
    Eigen::MatrixXd m = Eigen::Map<const Eigen::MatrixXd>(d.data() + i, static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
    i += r * c;
    return m;
  }
};
}  // namespace

std::vector<double> ReducedBasis::to_doubles() const {
  Writer w;
  w.num(kMagic);
  w.num(kVersion);
  w.vec(theta);
  w.vec(p);
  w.mat(U);
  w.mat(dU);
  w.mat(Phi);
  w.mat(W);
  w.vec(V);
  w.vec(dV);
  w.vec(wg);
  w.vec(wa);
  w.mat(b);
  w.mat(db);
  w.mat(c);
  w.mat(h);
  w.num(static_cast<double>(K.size()));
  for (std::size_t k = 0; k < K.size(); ++k) {
    w.mat(K[k]);
    w.mat(H[k]);
    w.mat(Kref[k]);
  }
  w.mat(gt);
  w.mat(gq);
  w.mat(gauge);
  w.vec(std::vector<double>(elements.begin(), elements.end()));
  w.vec(weights);
  w.mat(Gref);
  w.mat(pq);
  w.mat(pw);
  w.vec(std::vector<double>(stiff_part.begin(), stiff_part.end()));
  w.num(mesh_fingerprint);
  w.num(info.clusters);
  w.num(info.responses);
  w.num(info.soft_elements);
  w.num(info.pod_energy_left);
  w.num(info.ecsw_worst_residual);
  w.num(info.build_s);
  return std::move(w.d);
}

ReducedBasis ReducedBasis::from_doubles(const std::vector<double>& d) {
  Reader rd{d};
  if (rd.num() != kMagic || rd.num() != kVersion)
    throw InputError("reduced model: stored data are not a reduced basis of this pneufem version");
  ReducedBasis B;
  B.theta = rd.vec();
  B.p = rd.vec();
  B.U = rd.mat();
  B.dU = rd.mat();
  B.Phi = rd.mat();
  B.W = rd.mat();
  B.V = rd.vec();
  B.dV = rd.vec();
  B.wg = rd.vec();
  B.wa = rd.vec();
  B.b = rd.mat();
  B.db = rd.mat();
  B.c = rd.mat();
  B.h = rd.mat();
  const std::size_t ns = rd.count();
  for (std::size_t k = 0; k < ns; ++k) {
    B.K.push_back(rd.mat());
    B.H.push_back(rd.mat());
    B.Kref.push_back(rd.mat());
  }
  B.gt = rd.mat();
  B.gq = rd.mat();
  B.gauge = rd.mat();
  for (double e : rd.vec()) B.elements.push_back(static_cast<int>(e));
  B.weights = rd.vec();
  B.Gref = rd.mat();
  B.pq = rd.mat();
  B.pw = rd.mat();
  for (double s : rd.vec()) B.stiff_part.push_back(static_cast<char>(s));
  B.mesh_fingerprint = rd.num();
  B.info.clusters = static_cast<int>(rd.num());
  B.info.responses = static_cast<int>(rd.num());
  B.info.soft_elements = static_cast<int>(rd.num());
  B.info.pod_energy_left = rd.num();
  B.info.ecsw_worst_residual = rd.num();
  B.info.build_s = rd.num();
  const Eigen::Index r = B.Phi.cols(), n = static_cast<Eigen::Index>(B.theta.size());
  const bool ok = rd.i == d.size() && n >= 3 && B.p.size() == B.theta.size() && B.U.cols() == n && B.dU.cols() == n && B.W.cols() == n && B.wg.size() == B.theta.size() && B.wa.size() == B.theta.size() && B.db.cols() == n &&
                  B.U.rows() == B.Phi.rows() && B.V.size() == B.theta.size() && B.dV.size() == B.theta.size() &&
                  B.b.rows() == r && B.b.cols() == n && B.c.cols() == n && B.h.cols() == n && ns == B.theta.size() &&
                  B.gt.rows() == 3 && B.gt.cols() == n && B.gq.rows() == r && B.gauge.cols() == n &&
                  B.elements.size() == B.weights.size() && B.Gref.rows() == r + 1 &&
                  B.Gref.cols() == (n - 1) * (kRefSub + 1) && B.pq.rows() == r && B.pq.cols() == r * r &&
                  B.pw.rows() == r * r && B.pw.cols() == n;
  if (!ok) throw InputError("reduced model: stored basis is damaged (inconsistent sizes)");
  for (std::size_t k = 0; k < ns; ++k)
    if (B.K[k].rows() != r || B.H[k].rows() != r || B.Kref[k].rows() != r + 1)
      throw InputError("reduced model: stored basis is damaged (inconsistent sizes)");
  for (int e : B.elements)
    if (e < 0) throw InputError("reduced model: stored basis is damaged (element index)");
  return B;
}

}  // namespace pneufem
