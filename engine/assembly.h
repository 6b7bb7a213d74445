#pragma once
// Whole-mesh loops: internal forces, tangent stiffness, strain energy, follower pressure,
// gravity and lumped mass. This is the only place in the engine that knows about threads.
//
// Determinism: elements are greedily coloured so that no two elements of one colour share a
// node. Colours run one after another and the elements of a colour run in parallel (TBB),
// scattering straight into the global vectors/matrix. Every global entry therefore receives
// its contributions in the same order (colour order) whatever the number of threads, so the
// results are bit-for-bit identical for 1 and N threads, without atomics or per-thread buffers.
// Membrane layers (Model::membranes) are few triangles and are added serially after the
// coloured loop, so they keep this property.
#include <array>
#include <memory>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "engine/model.h"
#include "engine/tet_element.h"

namespace pneufem {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
class NonlocalAverage;

class Assembler {
 public:
  explicit Assembler(const Model& model);

  const Model& model() const { return model_; }
  const ElementGeometry& geometry() const { return geom_; }
  int num_dofs() const { return model_.num_dofs(); }
  int num_colours() const { return static_cast<int>(colour_ptr_.size()) - 1; }

  /// Material history layout: doubles per element (all its quadrature points) and offsets.
  std::size_t state_size() const { return state_offset_.back(); }
  std::span<const double> element_state(std::span<const double> all, int e) const {
    return all.subspan(state_offset_[e], state_offset_[e + 1] - state_offset_[e]);
  }
  std::vector<double> initial_state() const;

  /// Lumped nodal mass (kg), one value per node (solid elements and membranes).
  const Eigen::VectorXd& lumped_mass() const { return mass_; }

  /// Evaluates the internal force vector f_int(u) (N), the tangent dF/du (N/m, pattern of
  /// tangent_pattern(); fixed dofs are NOT applied) and the stored energy (J) for the requested
  /// outputs (nullptr = skip). Material history: reads `state_old`, writes the trial state into
  /// `state_new` (may be empty when state_size() == 0). Throws PhysicsError naming the first
  /// element (lowest index) with det F <= 0 or a non-finite stress, or a collapsed membrane
  /// triangle. Includes the model's membranes (engine/membrane.h).
  void internal(const Eigen::VectorXd& u, const TimeStep& ts, std::span<const double> state_old,
                std::span<double> state_new, Eigen::VectorXd* f_int, SparseMatrix* K, double* energy) const;

  /// Adds the follower-pressure load of pressure p (Pa, positive pushes into the solid) on the
  /// model's pressure faces to f_ext, and, when K is given, subtracts the (symmetrised) load
  /// stiffness d f_ext / du from K.
  void add_pressure(const Eigen::VectorXd& u, double p_Pa, Eigen::VectorXd& f_ext, SparseMatrix* K) const;
  /// Adds the consistent gravity load int rho N_a g dV (and rho t int N_a g dA of the membranes).
  void add_gravity(Eigen::VectorXd& f_ext, double scale = 1.0) const;  ///< scale: fraction of the weight (ramps)
  /// Volume enclosed by the pressure faces in the deformed configuration (m^3); exact for a
  /// closed cavity (or one closed by symmetry planes through the origin).
  double cavity_volume(const Eigen::VectorXd& u) const;

  /// Sparse pattern of the tangent (full symmetric storage, all 3x3 node blocks).
  SparseMatrix tangent_pattern() const;
  /// Zeroes the rows and columns of fixed dofs, puts `diag` on their diagonal.
  void apply_constraints(SparseMatrix& K, double diag) const;
  /// Zeroes the fixed entries of a vector.
  void zero_fixed(Eigen::VectorXd& v) const;

  /// Per-node upper bound on the row sums of |K| for the current (or given) tangent; used for
  /// stable-step estimates (Gershgorin) and for the fictitious masses of dynamic relaxation.
  Eigen::VectorXd row_abs_sums(const SparseMatrix& K) const;

  /// Per material point (element-major, geom nqp points each, every element): its fatigue damage
  /// and viscous strain (Material::fields), 2 values per point; zeros where a law has no history.
  /// The physical time step control compares these between states (engine/quasi_static.h); the
  /// Mullins variable is left out: it follows the load, not time.
  std::vector<double> history_scalars(std::span<const double> state) const;
  /// Element of point i of history_scalars.
  int element_of_point(int i) const { return i / geom_.nqp; }
  /// Material points of history_scalars (every element's quadrature points).
  int num_points() const { return model_.mesh.num_elements() * geom_.nqp; }
  /// Per material point, in history_scalars' order: the linear drive D of its law
  /// (Material::linear_drive_value, 6 values per point; zeros where the law has none). The
  /// time_control = "drive" step control compares these between states (engine/quasi_static.h).
  std::vector<double> linear_drives(std::span<const double> state) const;

  /// Material points whose law reports failure (PointFields::failed, e.g. fatigue damage >= d_fail)
  /// and all material points, per region (index = mesh region id; one entry for an untagged mesh).
  struct RegionFailures {
    std::vector<int> failed, points;
  };
  RegionFailures failed_points(std::span<const double> state) const;

  /// Non-local drivers (Material::nonlocal, engine/nonlocal.h): true when some material averages
  /// its driver over a radius. update_nonlocal() then reads every such point's driver at the
  /// committed state (u, state), averages it over the points of the same kind within the radius,
  /// and stores the average into `state` for the next increments; every driver calls it after each
  /// committed state (a no-op without non-local materials). Deterministic for any thread count.
  bool has_nonlocal() const { return nonlocal_ != nullptr; }
  void update_nonlocal(const Eigen::VectorXd& u, std::span<double> state) const;
  const NonlocalAverage* nonlocal_average() const { return nonlocal_.get(); }

  /// Deformation gradients and responses at the element's quadrature points (for output).
  void point_responses(const Eigen::VectorXd& u, int e, std::span<const double> state, std::span<Mat3> F,
                       std::span<PointResponse> out) const;

 private:
  // The constructor's parts, in the order it calls them.
  void build_element_loop();     ///< colour_ptr_, kelem_ and the per-position knodes_, kgrad_, kw_, kmat_
  void build_nonlocal();         ///< sets nonlocal_ / nl_element_ (constructor)
  void build_solid_mass();       ///< mass_: the elements' lumped mass
  void build_pattern();          ///< adj_ptr_, adj_, pair_slot_, and the membranes' mgeom_, mslot_ and mass
  void build_pressure_faces();   ///< pface_nodes_
  // internal() for one element type: the coloured element loop, then the membranes. Its kernels
  // (assembly.cpp) share a Pass, the call's inputs and outputs.
  struct Pass;
  template <int NPE, int NQP>
  void internal_impl(const Eigen::VectorXd& u, const TimeStep& ts, std::span<const double> state_old,
                     std::span<double> state_new, Eigen::VectorXd* f_int, SparseMatrix* K, double* energy) const;
  /// F at the points of the element at loop position `pos`.
  template <int NPE, int NQP>
  void deformation_gradients(const Eigen::VectorXd& u, int pos, std::array<Mat3, NQP>& F) const;
  /// The history of the element at loop position `pos` (untouched spans when no law has history).
  void element_states(const Pass& p, int pos, std::span<const double>& s_old, std::span<double>& s_new) const;
  /// Force only: loop positions [begin, end), in batches of StressBatch::kLanes points.
  template <int NPE, int NQP>
  void force_range(const Pass& p, int begin, int end) const;
  /// One batch of force_range: `m` elements at loop positions `bpos`, their F set in `b`.
  template <int NPE, int NQP>
  void force_batch(const Pass& p, const Material& mat, bool with_state, StressBatch& b, const int* bpos, int m) const;
  /// Force and tangent of the element at loop position `pos`.
  template <int NPE, int NQP>
  void tangent_element(const Pass& p, int pos) const;
  /// Adds the membranes' internal force, tangent and energy (serial); throws PhysicsError.
  template <int NPF>
  void add_membranes(const Eigen::VectorXd& u, const TimeStep& ts, Eigen::VectorXd* f_int, SparseMatrix* K,
                     double* energy) const;

  const Model& model_;
  ElementGeometry geom_;
  std::vector<std::size_t> state_offset_;       ///< per element (size ne + 1)
  Eigen::VectorXd mass_;
  // The element loop runs colour by colour (elements of one colour share no node, so their
  // scatter needs no atomics and the sums do not depend on the thread count). Its data are stored
  // in that order, colour after colour, so each sweep streams through memory: with the mesh's own
  // order the loop jumped through ~2 MB of geometry and stalled on cache misses (BENCHMARKS §4).
  // Position i of the loop is element kelem_[i]; colour c is positions [colour_ptr_[c], colour_ptr_[c+1]).
  std::vector<int> colour_ptr_;
  std::vector<int> kelem_;                ///< element of each loop position
  std::vector<int> knodes_;               ///< [i][a] node ids
  std::vector<double> kgrad_;             ///< [i][q][a][3] dN/dX, copied from geom_
  std::vector<double> kw_;                ///< [i][q] integration weights
  std::vector<const Material*> kmat_;     ///< [i] material
  // Tangent scatter: adjacency of each node (sorted) and, for loop position i and local pair
  // (a, b), the position of node a in the adjacency list of node b.
  std::vector<int> adj_ptr_, adj_;
  std::vector<std::uint16_t> pair_slot_;
  std::vector<int> col_ptr_;  ///< CSC column pointers of the pattern
  // Pressure faces in outward node order (global node ids), npf nodes per face.
  std::vector<int> pface_nodes_;
  // Membrane sets: reference geometry and pair slots (triangle t, local pair (a, b) at
  // [(t * npf + a) * npf + b], as pair_slot_).
  std::vector<MembraneGeometry> mgeom_;
  std::vector<std::vector<std::uint16_t>> mslot_;
  // Non-local averaging over the points (element-major, nqp each) of elements whose material has a
  // non-local driver (nl_element_[e]); null when there are none.
  std::shared_ptr<const NonlocalAverage> nonlocal_;
  std::vector<char> nl_element_;
};

}  // namespace pneufem
