#pragma once
// Lab test data for `pneufem fit-material`: which test a file holds, and its nominal stress-strain
// curve read from CSV with the units named in the header.
//
// A file is a table whose header names a strain and a stress column with their units:
//   strain,stress_kPa           nominal (engineering) strain, dimensionless, and nominal stress
//   stretch,stress_MPa          the stretch l = 1 + strain instead of the strain
//   strain_percent,stress_psi   strain in % (also "strain_%", "Strain (%)")
//   Engineering Strain;Engineering Stress (MPa)   a testing machine's export, units in brackets
// Names are read case-insensitively, with spaces, brackets and '-' taken as '_' and a leading
// "nominal_", "engineering_" or "eng_" dropped. Stress units: Pa, kPa, MPa, GPa, psi, N/mm^2 (N_mm2).
// Columns of true (Cauchy, logarithmic) stress or strain are recognised and skipped: the fit needs
// the nominal ones (Abaqus's test data convention). Any other column (time, force) is ignored.
// The delimiter is the header's: ';', else ',', else tabs or spaces; with ';' or tabs a decimal
// comma is read as a point. Lines before the header that are not data (a machine's metadata block)
// are skipped with a note; '#' lines and blank lines are skipped anywhere.
// Each row must be a tension point at a strain no lower than the row before (a loading curve). A row
// with zero or negative stress at a positive strain (a load-cell offset, a slack specimen) is left
// out with a note: under relative weights its residual would outweigh the rest of the curve.
#include <limits>
#include <string>
#include <vector>

#include "fit/fit.h"
#include "fit/inelastic.h"
#include "fit/volumetric.h"

namespace pneufem {

/// A DATA argument: "uniaxial:FILE", "biaxial:FILE" (or "equibiaxial:"), "planar:FILE" (or
/// "pure_shear:", "pureshear:"), "relaxation:FILE", "volumetric:FILE", or a FILE whose name contains
/// exactly one of those words.
struct TestFileSpec {
  enum class Kind { tension, relaxation, volumetric };
  fit::TestMode mode;
  std::string path;
  Kind kind = Kind::tension;  ///< relaxation (read_relaxation_csv), volumetric: `mode` is unused
};
TestFileSpec parse_test_spec(const std::string& arg);

/// The curve of `path` (stresses in Pa). Points above `max_strain` are dropped (a note says how
/// many). Notes (skipped lines, true-stress columns, rows left out) are appended to `notes`.
/// Throws InputError "<path>:<line>: ..." with what to do.
/// With `cycles` (loading-unloading data for a Mullins fit) the strain may fall; it must still be >= 0.
fit::TestCurve read_test_csv(const std::string& path, fit::TestMode mode, std::vector<std::string>& notes,
                             double max_strain = std::numeric_limits<double>::infinity(), bool cycles = false);

/// A relaxation test: a step strain held. The header names the time since the step (time_s, time_ms,
/// time_min, time_h, "Time (s)") and either the normalised stress g_R (g_R, g, normalized_modulus,
/// normalised_modulus, modulus_ratio, stress_ratio), or the stress with a unit (stress_kPa, ...), which
/// is then divided by the first row's stress (a note says so; that row should be right after the
/// step). The time must increase and be >= 0. Throws InputError "<path>:<line>: ...".
fit::RelaxationCurve read_relaxation_csv(const std::string& path, std::vector<std::string>& notes);

/// A volumetric test: the header names the volume ratio (volume_ratio, J, V_V0) and the pressure with
/// its unit (pressure_kPa, pressure_MPa, ...; > 0 in compression). J must be > 0.
fit::VolumetricCurve read_volumetric_csv(const std::string& path, std::vector<std::string>& notes);

}  // namespace pneufem
