#include "damage/decorator.h"

#include <cassert>

namespace pneufem {

MaterialDecorator::MaterialDecorator(MaterialPtr base, std::string effect, int own)
    : base_(std::move(base)), effect_(std::move(effect)), own_(own) {
  detail::require_split_base(base_, effect_);
}

}  // namespace pneufem

namespace pneufem::detail {

bool stress_base(const Material& base, StressBatch& b, const TimeStep& step, std::span<const double> state_old,
                 std::span<double> state_new, std::size_t own) {
  const std::size_t nb = static_cast<std::size_t>(base.state_size());
  if (nb > kMaxBaseState) return false;
  const std::size_t n = static_cast<std::size_t>(b.n), ss = own + nb;
  assert(state_old.empty() || state_old.size() >= n * ss);
  assert(state_new.empty() || state_new.size() >= n * ss);
  // The engine visits elements in colour order, so each element's state blocks are cache misses:
  // requesting all their lines up front overlaps the misses instead of meeting them one by one (the
  // gather below, then each layer's own reads and writes): ~20 % of the story material's force pass.
  // (A nested layer prefetches its stack buffers again, which costs next to nothing.)
  for (std::size_t i = 0; i < n * ss; i += 8) {  // 8 doubles = one 64-byte line
    if (!state_old.empty()) __builtin_prefetch(state_old.data() + i, 0);
    if (!state_new.empty()) __builtin_prefetch(state_new.data() + i, 1);
  }
  if (nb == 0) {  // an elastic base: nothing to gather
    base.stress(b, step, {}, {});
    return true;
  }
  double base_old[StressBatch::kLanes * kMaxBaseState], base_new[StressBatch::kLanes * kMaxBaseState];
  if (!state_old.empty())
    for (std::size_t q = 0; q < n; ++q)
      for (std::size_t i = 0; i < nb; ++i) base_old[q * nb + i] = state_old[q * ss + own + i];
  const std::span<const double> old_view = state_old.empty() ? std::span<const double>{} : std::span<const double>(base_old, n * nb);
  const std::span<double> new_view = state_new.empty() ? std::span<double>{} : std::span<double>(base_new, n * nb);
  base.stress(b, step, old_view, new_view);
  // Every law writes its whole trial block (material.h), so nothing of base_new is left unset.
  if (!state_new.empty())
    for (std::size_t q = 0; q < n; ++q)
      for (std::size_t i = 0; i < nb; ++i) state_new[q * ss + own + i] = base_new[q * nb + i];
  return true;
}

void require_potential_base(const MaterialPtr& base, const std::string& effect) {
  if (!base->isochoric_energy_is_potential())
    throw InputError(effect + ": cannot wrap '" + base->name() + "': " + effect +
                     " is driven by the base's isochoric energy, which must be a potential of its stress; "
                     "apply the effects in the order viscoelastic(fatigue(mullins(base)))");
}

}  // namespace pneufem::detail
