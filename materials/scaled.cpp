#include "materials/scaled.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"

namespace pneufem {

ScaledMaterial::ScaledMaterial(MaterialPtr base, double scale) : base_(std::move(base)), scale_(scale) {
  if (!base_) throw InputError("stiffness_scale: no base material given");
  if (!(std::isfinite(scale_) && scale_ > 0.0)) {
    std::ostringstream s;
    s << "stiffness_scale must be a finite number > 0 (1 = unscaled), got " << scale_;
    throw InputError(s.str());
  }
}

std::string ScaledMaterial::name() const {
  std::ostringstream s;
  s << "scaled(" << base_->name() << ", " << scale_ << ")";
  return s.str();
}

void ScaledMaterial::evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                              std::span<double> state_new, std::span<PointResponse> out, bool tangent) const {
  base_->evaluate(F, step, state_old, state_new, out, tangent);
  for (PointResponse& r : out) {
    r.psi_iso *= scale_;
    r.psi_vol *= scale_;
    r.P_iso *= scale_;
    r.P_vol *= scale_;
    if (tangent) {
      r.A_iso *= scale_;
      r.A_vol *= scale_;
    }
  }
}

void ScaledMaterial::stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
                            std::span<double> state_new) const {
  base_->stress(b, step, state_old, state_new);
  for (int l = 0; l < b.n; ++l) {
    b.psi_iso[l] *= scale_;
    b.psi_vol[l] *= scale_;
    for (int k = 0; k < 9; ++k) {
      b.P_iso[k][l] *= scale_;
      b.P_vol[k][l] *= scale_;
    }
  }
}

MaterialPtr scale_material(MaterialPtr base, double scale) {
  if (scale == 1.0 && base) return base;
  return std::make_shared<const ScaledMaterial>(std::move(base), scale);
}

}  // namespace pneufem
