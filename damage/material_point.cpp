#include "damage/material_point.h"

#include <algorithm>

#include "core/errors.h"

namespace pneufem {

MaterialPoint::MaterialPoint(MaterialPtr material) : material_(std::move(material)) {
  if (!material_) throw InputError("MaterialPoint: no material given");
  const auto n = static_cast<std::size_t>(material_->state_size());
  committed_.assign(n, 0.0);
  material_->init_state(committed_);
  trial_ = committed_;
}

PointResponse MaterialPoint::trial(const Mat3& F, double dt_s, bool tangent) {
  PointResponse r;
  material_->evaluate(std::span<const Mat3>(&F, 1), TimeStep{time_s_ + dt_s, dt_s}, committed_, trial_,
                      std::span<PointResponse>(&r, 1), tangent);
  trial_dt_s_ = dt_s;
  return r;
}

void MaterialPoint::commit() {
  committed_ = trial_;
  time_s_ += trial_dt_s_;
  trial_dt_s_ = 0.0;
}

PointResponse MaterialPoint::advance(const Mat3& F, double dt_s, bool tangent) {
  const PointResponse r = trial(F, dt_s, tangent);
  commit();
  return r;
}

void MaterialPoint::set_committed_state(std::span<const double> state) {
  if (state.size() != committed_.size())
    throw InputError("MaterialPoint: state of size " + std::to_string(state.size()) + " given, the material '" +
                     material_->name() + "' needs " + std::to_string(committed_.size()));
  std::copy(state.begin(), state.end(), committed_.begin());
  trial_ = committed_;
}

}  // namespace pneufem
