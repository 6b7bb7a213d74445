// A deck's materials as a layer of the scene (scenes/deck_materials.h).
#include "scenes/deck_materials.h"

#include <algorithm>
#include <cctype>

#include "core/errors.h"
#include "core/message_text.h"
#include "core/number_text.h"

namespace pneufem {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// The scene table name of a deck material: its name in lower case, which must be a plain TOML key.
std::string table_name(const InpMaterial& m) {
  const bool plain = std::all_of(m.name.begin(), m.name.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '_' || c == '-';
  });
  if (!plain)
    throw InputError(printable(m.where + ": *MATERIAL, NAME=" + m.name + ": the name cannot be a scene table "
                               "(materials.<name>); rename the material with letters, digits, '_' and '-' only"));
  return lower(m.name);
}

toml::array array_of(const std::vector<double>& v) {
  toml::array a;
  for (double x : v) a.push_back(x);
  return a;
}

/// Adds `value` at table[key] and records where it came from.
template <class V>
void put(toml::table& t, DeckInfo::Material& m, DeckInfo& info, const std::string& key, V&& value, const std::string& where) {
  t.insert_or_assign(key, std::forward<V>(value));
  const std::string full = m.table + "." + key;
  m.keys.push_back(full);
  info.origins[full] = where;
}

/// The [materials.NAME] table of one deck material.
toml::table material_table(const InpMaterial& d, DeckInfo::Material& m, DeckInfo& info, const std::string& unit,
                           const DeckDefaults& defaults) {
  toml::table t;
  if (d.model == "test_data") {
    m.test_data = true;
  } else {
    put(t, m, info, "model", d.model, d.law_where);
    if (d.model == "ogden") {
      put(t, m, info, "mu_MPa", array_of(d.mu_MPa), d.law_where);
      put(t, m, info, "alpha", array_of(d.alpha), d.law_where);
    }
    for (const auto& [key, v] : d.constants) put(t, m, info, key, v, d.law_where);
    if (d.model != "linear_elastic") {
      m.incompressible = !(d.D1_per_MPa > 0.0);
      put(t, m, info, "K_over_mu", m.incompressible ? defaults.K_over_mu : k_over_mu_from_d1(d.D1_per_MPa, d.mu0_MPa),
          d.law_where);
    }
  }
  m.no_density = !d.density;
  put(t, m, info, "density_kg_m3", d.density ? density_from_deck(*d.density, unit) : defaults.density_kg_m3,
      d.density ? d.density_where : d.where);
  if (d.mullins) {
    toml::table mu;
    DeckInfo::Material sub;
    sub.table = m.table + ".mullins";
    put(mu, sub, info, "enabled", true, d.mullins->where);
    put(mu, sub, info, "r", d.mullins->r, d.mullins->where);
    put(mu, sub, info, "m_MPa", d.mullins->m_MPa, d.mullins->where);
    put(mu, sub, info, "beta", d.mullins->beta, d.mullins->where);
    m.keys.insert(m.keys.end(), sub.keys.begin(), sub.keys.end());
    t.insert_or_assign("mullins", std::move(mu));
  }
  if (d.prony || !d.moduli.empty()) {
    // MODULI= without *VISCOELASTIC: the convention is kept for a scene that switches it on.
    toml::table v;
    DeckInfo::Material sub;
    sub.table = m.table + ".viscoelastic";
    put(v, sub, info, "enabled", d.prony.has_value(), d.prony ? d.prony->where : d.moduli_where);
    if (d.prony) {
      put(v, sub, info, "gamma", array_of(gamma_from_abaqus_g(d.prony->g)), d.prony->where);
      put(v, sub, info, "tau_s", array_of(d.prony->tau_s), d.prony->where);
    }
    put(v, sub, info, "moduli", d.moduli.empty() ? std::string("instantaneous") : d.moduli,
        d.moduli.empty() ? d.prony->where : d.moduli_where);
    m.keys.insert(m.keys.end(), sub.keys.begin(), sub.keys.end());
    t.insert_or_assign("viscoelastic", std::move(v));
  }
  return t;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

}  // namespace

DeckLayer deck_layer(const std::string& path, const std::string& length_unit, const DeckDefaults& defaults) {
  const InpMaterials deck = read_inp_materials(path, length_unit);
  DeckLayer out;
  out.info.deck = path;
  out.info.length_unit = length_unit;
  out.info.read_notes = deck.notes;
  if (deck.materials.empty() && deck.sections.empty()) return out;
  toml::table materials;
  for (const InpMaterial& d : deck.materials) {
    DeckInfo::Material m;
    m.table = "materials." + table_name(d);
    m.deck_name = d.name;
    m.where = d.where;
    m.law_where = d.law_where;
    materials.insert_or_assign(table_name(d), material_table(d, m, out.info, length_unit, defaults));
    out.info.materials.push_back(std::move(m));
  }
  out.table.insert_or_assign("materials", std::move(materials));
  if (!deck.sections.empty()) {
    toml::array parts;
    for (const InpSection& s : deck.sections) {
      InpSection named = s;
      named.material = lower(s.material);
      out.info.sections.push_back(named);
      parts.push_back(toml::table{{"elset", s.elset}, {"material", named.material}});
    }
    out.table.insert_or_assign("parts", std::move(parts));
    out.info.origins["parts"] = deck.sections.front().where;
  }
  return out;
}

std::vector<std::string> deck_notes(const DeckInfo& info, const MergedScene& s) {
  std::vector<std::string> notes;
  const auto from_deck = [&](const std::string& key) {
    const auto it = info.origins.find(key);
    return it != info.origins.end() && s.has(key) && s.origin_of(key) == it->second;
  };
  std::vector<std::string> used;  // the materials of the scene's parts
  for (int i = 0; i < s.array_size("parts"); ++i) {
    const std::string key = "parts[" + std::to_string(i) + "].material";
    try {
      used.push_back(s.string(key));
    } catch (const InputError&) {
      // a part without a material string: build_model names it
    }
  }
  for (const DeckInfo::Material& m : info.materials) {
    const std::string name = m.table.substr(std::string("materials.").size());
    const bool is_used = std::find(used.begin(), used.end(), name) != used.end();
    const std::string model = m.table + ".model";
    const bool scene_law = s.has(model) && s.origin(model) != "default scene" && !from_deck(model);
    if (m.test_data && is_used && !scene_law)
      throw InputError(printable(
          m.law_where + ": *MATERIAL " + m.deck_name + " has *HYPERELASTIC, TEST DATA INPUT, and the scene's parts use it " +
          "(materials." + name + "), but pneufem does not fit constants while it loads a scene; run `pneufem fit-material " +
          "deck:" + info.deck + " --deck-material " + m.deck_name + " --name " + name +
          (info.length_unit == "m" ? " --deck-length-unit m" : "") + " --out DIR` and put the [" +
          m.table + "] block of DIR/material.toml in the scene (the scene's keys win over the deck's)"));
    std::vector<std::string> taken, kept;
    for (const std::string& key : m.keys) {
      const std::string rel = key.substr(m.table.size() + 1);
      if (from_deck(key))
        taken.push_back(rel);
      else if (s.has(key))
        kept.push_back(rel + " (" + s.origin(key) + ")");
    }
    std::string note = m.table + (taken.empty() ? ": the scene sets every key" : " from the deck") + " (*MATERIAL " +
                       m.deck_name + ", " + m.where + ")";
    if (!taken.empty()) note += ": " + join(taken);
    if (!kept.empty() && !taken.empty()) note += "; the scene's own: " + join(kept);
    if (m.test_data) note += "; its *HYPERELASTIC is TEST DATA INPUT (no constants: fit them with `pneufem fit-material`)";
    if (!is_used) note += "; used by no part";
    notes.push_back(note);
    if (m.incompressible && from_deck(m.table + ".K_over_mu"))
      notes.push_back(m.table + ".K_over_mu = " + short_num(s.number(m.table + ".K_over_mu")) + ": the deck's D1 = 0 (" +
                      m.law_where + ") is incompressible in Abaqus, and pneufem needs a finite bulk modulus; this is the " +
                      "default scene's ratio K0/mu0 (set " + m.table + ".K_over_mu to change it)");
    if (m.no_density && from_deck(m.table + ".density_kg_m3"))
      notes.push_back(m.table + ".density_kg_m3 = " + short_num(s.number(m.table + ".density_kg_m3")) + ": the deck's *MATERIAL " +
                      m.deck_name + " has no *DENSITY; this is the default scene's (it matters in explicit runs and "
                      "with gravity; set " + m.table + ".density_kg_m3 to change it)");
  }
  if (!info.sections.empty()) {
    std::vector<std::string> pairs;
    for (const InpSection& sec : info.sections) pairs.push_back(sec.elset + " -> " + sec.material + " (" + sec.where + ")");
    if (from_deck("parts"))
      notes.push_back("parts from the deck's *SOLID SECTION lines: " + join(pairs));
    else
      notes.push_back("the deck's *SOLID SECTION lines are not used: the scene sets [[parts]] (" + s.origin("parts") + ")");
  }
  for (const std::string& n : info.read_notes) notes.push_back(n);
  return notes;
}

}  // namespace pneufem
