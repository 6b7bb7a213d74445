#pragma once
// VTK output: one VTU (XML unstructured grid) per reported state and a PVD time-series index,
// written atomically (temporary file + rename) so an interrupted run never leaves a
// half-written file. VTK headers stay inside the .cpp (they are heavy).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "engine/assembly.h"

namespace pneufem {

/// Point/cell fields of one state, computed from the engine's results.
struct StateFields {
  // per node
  std::vector<Eigen::Vector3d> displacement_m;
  // per element (averaged over its quadrature points)
  std::vector<Eigen::Matrix3d> cauchy_Pa;
  std::vector<double> von_mises_Pa;
  std::vector<double> max_principal_stretch;
  std::vector<double> energy_density_J_m3;
  std::vector<double> damage;           ///< from Material::fields
  std::vector<double> W_max_J_m3;
  std::vector<double> viscous_strain;
};

/// Evaluates the fields of the state (u, committed material state).
StateFields compute_fields(const Assembler& assembler, const Eigen::VectorXd& u, const std::vector<double>& state);

/// Writes `path` (.vtu) with the mesh (quadratic tets for Tet10) in the reference configuration,
/// the point field "displacement_m" (apply ParaView's Warp By Vector to see the deformed shape),
/// and cell fields cauchy_stress_Pa (9 comps), von_mises_Pa, max_principal_stretch,
/// strain_energy_density_J_m3, damage, W_max_J_m3, viscous_strain, region_id, material_id.
/// The stiff layer (parts stiffer in shear than the softest by StaticOptions::stiff_modulus_ratio,
/// 100: the fabric) has its von Mises stress in its own field, fabric_von_mises_Pa, and NaN in
/// von_mises_Pa, so colouring by von_mises_Pa shows the silicone's range. Point data besides the
/// displacement: cauchy_stress_Pa and von_mises_Pa (means over the soft elements around each node),
/// fabric_von_mises_Pa (over the stiff ones); NaN at nodes with no such element.
/// Field data: time_s, trial, pressure_kPa, angle_deg.
void write_vtu(const std::string& path, const Model& model, const StateFields& fields, double time_s, int trial,
               double pressure_kPa, double angle_deg);

/// Collects the VTU files of a run and writes the .pvd index after each addition (atomic).
class PvdSeries {
 public:
  explicit PvdSeries(std::string pvd_path);
  /// Adds a state (an absolute file name is made relative to the .pvd's directory) and rewrites the
  /// index. std::invalid_argument for a non-finite time or a file name with a control character
  /// (XML 1.0 cannot hold one); the series is unchanged when the write fails.
  void add(double time_s, const std::string& vtu_file_relative);
  const std::string& path() const { return path_; }

 private:
  void flush() const;
  std::string path_;
  std::vector<std::pair<double, std::string>> entries_;
};

}  // namespace pneufem
