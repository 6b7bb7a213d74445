#pragma once
// The materials of an Abaqus / CalculiX deck (.inp) and the sections that give them to element sets,
// read for a scene (scenes/deck_materials.h turns them into the scene's [materials.NAME] tables and
// [[parts]] where the scene does not set them). A pass of its own over the deck's lines (with
// *INCLUDE): it reads nothing of the mesh, so a scene knows its materials before any mesh is built.
//
// Keywords (Abaqus Keywords Reference; names and values case-insensitive):
//   *MATERIAL, NAME=                 starts a material; the options below belong to it up to the next
//                                    keyword that is not a material option
//   *HYPERELASTIC, <law>[, N=][, MODULI=][, TEST DATA INPUT]
//        YEOH                        C10, C20, C30, D1, D2, D3
//        NEO HOOKE                   C10, D1
//        MOONEY-RIVLIN               C10, C01, D1
//        POLYNOMIAL, N=1             C10, C01, D1 (Mooney-Rivlin; also no law named: Abaqus's default)
//        REDUCED POLYNOMIAL, N=1..3  C10[, C20[, C30]], D1[, D2[, D3]] (neo-Hookean, Yeoh)
//        OGDEN, N=1..3               mu1, alpha1, ..., muN, alphaN, D1, ..., DN (8 values a line)
//      Abaqus's Ogden convention W = sum 2 mu_i / alpha_i^2 (lb1^alpha_i + ... - 3) is pneufem's
//      (materials/ogden.h), so mu_i are taken as written. D1 = 2/K0 (U = (J - 1)^2 / D1); pneufem's
//      volumetric energy is that one term, so D2, D3, ... must be 0. D1 = 0 (Abaqus: incompressible)
//      keeps the scene's K_over_mu (pneufem needs a finite bulk modulus), with a note.
//      TEST DATA INPUT: the constants are to be fitted (`pneufem fit-material deck:FILE`); the test
//      data keywords after it (*UNIAXIAL TEST DATA, ...) are passed over here.
//   *ELASTIC[, TYPE=ISOTROPIC][, MODULI=]   E, nu            (St Venant-Kirchhoff under NLGEOM)
//   *DENSITY                                rho
//   *MULLINS EFFECT                         r, m, beta       (Ogden-Roxburgh, as damage/mullins.h)
//   *VISCOELASTIC, TIME=PRONY[, MODULI=]    g_i, k_i, tau_i  one line per term (1..3); k_i must be 0
//        (pneufem relaxes the isochoric response only, damage/viscoelastic.h)
//   *SOLID SECTION, ELSET=, MATERIAL=       element set -> material (the data line, if any, is passed over)
// Material options with no mechanical effect in pneufem's runs (*CONDUCTIVITY, *SPECIFIC HEAT,
// *EXPANSION, *DAMPING, ...) are passed over with a note; options that change the mechanics and that
// pneufem does not model (*PLASTIC, *HYPERFOAM, *CREEP, *USER MATERIAL, ...), any parameter not listed
// above, a law pneufem does not have, temperature-dependent data (more values or lines than the law
// has), an option outside a *MATERIAL, a material without an elastic law and a section naming a
// material the deck does not define are errors "<file>:<line>: *KEYWORD ...: what; what to do".
//
// Units. Deck numbers carry none: the deck's length unit names its consistent system, mm (N, MPa,
// tonne, s: pneufem's exported decks) or m (N, Pa, kg, s). Stresses are returned in MPa (a mm deck's
// numbers unchanged), densities as written (convert with density_from_deck).
#include <optional>
#include <string>
#include <vector>

namespace pneufem {

/// One *MATERIAL of a deck, its constants in MPa (stresses) and as written (the rest).
struct InpMaterial {
  std::string name;   ///< NAME= as written
  std::string where;  ///< "<file>:<line>" of the *MATERIAL line
  /// The scene's model word: "yeoh", "neo_hookean", "mooney_rivlin", "ogden", "linear_elastic"; or
  /// "test_data" (*HYPERELASTIC, TEST DATA INPUT: nothing to take until it is fitted).
  std::string model;
  std::string law_keyword;  ///< "*HYPERELASTIC, YEOH", for notes
  std::string law_where;    ///< "<file>:<line>" of that keyword
  /// The law's constants as scene keys, in the scene's order: C10_MPa, C20_MPa, C30_MPa, C01_MPa (the
  /// ones the law has), E_MPa, nu. Ogden's are in mu_MPa and alpha.
  std::vector<std::pair<std::string, double>> constants;
  std::vector<double> mu_MPa, alpha;  ///< Ogden (Abaqus convention, materials/ogden.h)
  double mu0_MPa = 0.0;               ///< initial shear modulus of the law (2 C10, 2 (C10 + C01), sum mu)
  double D1_per_MPa = 0.0;            ///< 0: incompressible in Abaqus (the scene's K_over_mu stays)
  std::optional<double> density;      ///< as written (deck units)
  std::string density_where;
  struct Mullins {
    double r = 0.0, m_MPa = 0.0, beta = 0.0;
    std::string where;
  };
  std::optional<Mullins> mullins;
  struct Prony {
    std::vector<double> g, tau_s;  ///< Abaqus g_i (fractions of the instantaneous modulus), tau_i
    std::string where;
  };
  std::optional<Prony> prony;
  std::string moduli;  ///< "instantaneous" / "long_term" from MODULI=, or "" (not given)
  std::string moduli_where;
};

/// A *SOLID SECTION: its element set as written, the material's NAME= as the *MATERIAL line writes it.
struct InpSection {
  std::string elset;
  std::string material;
  std::string where;
};

struct InpMaterials {
  std::vector<InpMaterial> materials;  ///< in order of their *MATERIAL lines
  std::vector<InpSection> sections;    ///< in order
  std::vector<std::string> notes;      ///< options passed over
};

/// Reads the materials and sections of the deck at `path` (length_unit "mm" or "m", see above).
/// Throws InputError as described above; a deck that cannot be opened too.
InpMaterials read_inp_materials(const std::string& path, const std::string& length_unit);

// ---- the conversions the writer and the reader share, so that a written deck reads back to the
// ---- identical numbers (scenes/calculix_deck.cpp writes with these; deck_materials.cpp inverts them)

/// Abaqus's D1 = 2/K0 of a law with initial shear modulus mu0 (MPa) and K0 = K_over_mu * mu0.
double abaqus_d1(double K_over_mu, double mu0_MPa);
/// A mm deck's density (tonne/mm^3) of rho kg/m^3, or an m deck's (kg/m^3).
double deck_density(double rho_kg_m3, const std::string& length_unit);
/// Abaqus's Prony g_i of pneufem's gamma_i: g_i = gamma_i / (1 + sum gamma) (damage/viscoelastic.h).
std::vector<double> abaqus_g(const std::vector<double>& gamma);

/// The scene's K_over_mu of a deck's D1: 2 / (D1 mu0), as the shortest decimal whose abaqus_d1 is D1
/// exactly (so the K_over_mu a deck was written from comes back: 100, not 99.99999999999999). Exact for
/// ratios of up to 15 significant digits: the ratios with one D1 span ~2 ulps, which holds no other
/// decimal that short. A hand-written D1 that no ratio reproduces gives 2 / (D1 mu0).
double k_over_mu_from_d1(double D1_per_MPa, double mu0_MPa);
/// kg/m^3 of a deck density, the shortest decimal whose deck_density is the deck's number exactly.
double density_from_deck(double rho_deck, const std::string& length_unit);
/// gamma_i = g_i / (1 - sum g), each the shortest decimal for which abaqus_g gives the deck's g exactly
/// when there is one (else the quotient). Needs sum g < 1 (checked by the reader).
std::vector<double> gamma_from_abaqus_g(const std::vector<double>& g);

}  // namespace pneufem
