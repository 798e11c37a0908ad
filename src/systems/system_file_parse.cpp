// src/systems/system_file_parse.cpp — the TOML layer of system files:
// toml++ parses; this file turns the table into a SystemDefinition and checks
// everything that needs no expression algebra (names, sizes, S and J skew,
// designs), each problem a SystemFileError at the key's line with the fix.
// The designs ([initial], [control], [measurement], [plots]):
// system_file_designs.cpp.
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>
#include <regex>
#include <set>
#include <sstream>

#include "phnn/common/counted.h"
#include "phnn/common/closest_name.h"
#include "phnn/systems/system_file.h"
#include "systems/system_file_reader.h"

namespace phnn {

SystemFileError::SystemFileError(const std::string& file, int line, const std::string& message)
    : std::invalid_argument(line > 0 ? file + ":" + std::to_string(line) + ": " + message
                                     : file + ": " + message),
      file_(file),
      line_(line) {}

int SystemDefinition::line_of(const std::string& key) const {
  const auto it = lines.find(key);
  return it == lines.end() ? 0 : it->second;
}

namespace {

const std::vector<std::string> kTopKeys = {"name",   "description", "states", "units",
                                           "inputs", "input_units", "ports",  "H",
                                           "z",      "S",           "J",      "parameters",
                                           "initial", "control",    "plots", "measurement"};

// Names GiNaC or muParser read as functions or constants.
const std::set<std::string> kReserved = {
    "sin",  "cos",  "tan",   "asin",  "acos",  "atan",  "sinh", "cosh", "tanh", "asinh",
    "acosh", "atanh", "exp", "log",   "sqrt",  "abs",   "pow",  "Pi",   "I",    "Euler",
    "Catalan", "D", "ln",    "log2",  "log10", "sign",  "rint", "min",  "max",  "sum",
    "avg",  "fabs", "csgn",  "step",  "zeta",  "tgamma", "lgamma", "beta", "psi", "factorial"};

using Reader = internal::SystemTomlReader;
using internal::read_control;
using internal::read_initial;
using internal::read_measurement;
using internal::read_plots;


void check_name(const Reader& r, int line, const std::string& name, const std::string& what,
                std::set<std::string>* seen) {
  static const std::regex kIdentifier("[A-Za-z][A-Za-z0-9_]*");
  if (!std::regex_match(name, kIdentifier)) {
    r.fail(line, what + " name \"" + name +
                     "\" is not an identifier; use letters, digits and _, starting with a letter");
  }
  if (kReserved.count(name) || name.rfind("phnn_", 0) == 0) {
    r.fail(line, what + " name \"" + name +
                     "\" is reserved (a function or constant of the expressions); rename it");
  }
  if (!seen->insert(name).second) {
    r.fail(line, what + " name \"" + name +
                     "\" is used twice; states, inputs, ports and parameters need distinct names");
  }
}

void check_skew(const Reader& r, int line, const MatX& m, const std::string& key) {
  const double scale = std::max(1.0, m.cwiseAbs().maxCoeff());
  for (int i = 0; i < m.rows(); ++i) {
    for (int j = 0; j <= i; ++j) {
      if (i == j && std::abs(2 * m(i, i)) > 1e-12 * scale) {
        const std::string k = std::to_string(i + 1);
        const std::string at = key + "[" + k + "][" + k + "]";
        r.fail(line, "\"" + key + "\" is not skew-symmetric: " + at + " = " +
                         Reader::num(m(i, i)) + " is on the diagonal, which must be 0 (" + at +
                         " = -" + at + "); " + key + " = -" + key +
                         "^T is what makes the power balance hold");
      }
      if (std::abs(m(i, j) + m(j, i)) > 1e-12 * scale) {
        r.fail(line, "\"" + key + "\" is not skew-symmetric: " + key + "[" + std::to_string(i + 1) +
                         "][" + std::to_string(j + 1) + "] = " + Reader::num(m(i, j)) + " but " +
                         key + "[" + std::to_string(j + 1) + "][" + std::to_string(i + 1) +
                         "] = " + Reader::num(m(j, i)) + "; " + key + " = -" + key +
                         "^T is what makes the power balance hold");
      }
    }
  }
}

void read_names(const Reader& r, const toml::table& t, SystemDefinition* def) {
  std::set<std::string> seen;
  const toml::node* states = r.get(t, "states", true, "", 1);
  def->lines["states"] = Reader::line(*states);
  def->states = r.strings(*states, "states");
  if (def->states.empty()) r.fail(Reader::line(*states), "\"states\" is empty; name at least one state");
  for (const auto& s : def->states) check_name(r, Reader::line(*states), s, "state", &seen);
  auto optional_names = [&](const char* key, const char* what, std::vector<std::string>* out) {
    if (const toml::node* n = r.get(t, key, false, "", 0)) {
      def->lines[key] = Reader::line(*n);
      *out = r.strings(*n, key);
      for (const auto& s : *out) check_name(r, Reader::line(*n), s, what, &seen);
    }
  };
  optional_names("inputs", "input", &def->inputs);
  optional_names("ports", "dissipation port", &def->ports);
  auto units = [&](const char* key, std::size_t count, std::vector<std::string>* out) {
    if (const toml::node* n = r.get(t, key, false, "", 0)) {
      *out = r.strings(*n, key);
      if (out->size() != count) {
        r.fail(Reader::line(*n), "\"" + std::string(key) + "\" has " + std::to_string(out->size()) +
                                     " entries for " + std::to_string(count) + " names; give one unit each");
      }
    } else {
      out->assign(count, "");
    }
  };
  units("units", def->states.size(), &def->state_units);
  units("input_units", def->inputs.size(), &def->input_units);
  if (const toml::node* p = r.get(t, "parameters", false, "", 0)) {
    const toml::table* pt = p->as_table();
    if (pt == nullptr) r.fail(Reader::line(*p), "[parameters] must be a table of name = number");
    def->lines["parameters"] = Reader::line(*p);
    for (const auto& [key, value] : *pt) {
      const std::string name(key.str());
      if (std::find(kTopKeys.begin(), kTopKeys.end(), name) != kTopKeys.end() && !value.is_number()) {
        r.fail(Reader::line(value), "\"" + name + "\" is read as a parameter because it follows the "
                                    "[parameters] header; in TOML a key belongs to the table above "
                                    "it: move " + name + " (and the other top-level keys) above the "
                                    "first [table]");
      }
      check_name(r, Reader::line(value), name, "parameter", &seen);
      def->parameters.emplace_back(name, r.number(value, name));
      def->lines["parameters." + name] = Reader::line(value);
    }
  }
}

// One z_k(w) per port; without ports, the ports to declare.
void check_ports_for_z(const Reader& r, int line, std::size_t expressions, std::size_t ports) {
  if (expressions == ports) return;
  r.fail(line, "\"z\" has " + counted(static_cast<long long>(expressions), "expression") + " for " +
                   counted(static_cast<long long>(ports), "port") +
                   (ports == 0 ? "; z acts on ports: declare them, one name per z_k(w), e.g. ports = "
                                 "[\"w\"], and give S their rows and columns (sweeps/FORMAT.md, "
                                 "\"System files\")"
                               : "; give one z_k(w) per port in \"ports\""));
}

void read_structure(const Reader& r, const toml::table& t, SystemDefinition* def) {
  const int nx = static_cast<int>(def->states.size());
  const int nw = static_cast<int>(def->ports.size());
  const int nu = static_cast<int>(def->inputs.size());
  const toml::node* s = r.get(t, "S", true, " (the structure matrix, rows and columns ordered "
                                            "states, ports, inputs)", 1);
  def->lines["S"] = Reader::line(*s);
  if (nx + nw + nu > kMaxDimension) {
    r.fail(Reader::line(*s), std::to_string(nx) + " states, " + std::to_string(nw) + " ports and " +
                                 std::to_string(nu) + " inputs make S " + std::to_string(nx + nw + nu) +
                                 " square; at most " + std::to_string(kMaxDimension) +
                                 " is supported: reduce the model or raise kMaxDimension "
                                 "(include/phnn/systems/ph_system.h) and rebuild");
  }
  // S's size follows from the ports: a z without its ports is named before S.
  if (const toml::node* z = r.get(t, "z", false, "", 0); z != nullptr && z->is_array()) {
    check_ports_for_z(r, Reader::line(*z), z->as_array()->size(), def->ports.size());
  }
  def->S = r.matrix(*s, "S", nx + nw + nu);
  check_skew(r, Reader::line(*s), def->S, "S");
  if (nw > 0 && def->S.block(nx, nx, nw, nw).cwiseAbs().maxCoeff() != 0.0) {
    r.fail(Reader::line(*s), "the port block S_ww of \"S\" (rows and columns " +
                                 std::to_string(nx + 1) + ".." + std::to_string(nx + nw) +
                                 ") must be zero, so that w = S_wx gradH + S_wu u is explicit");
  }
  if (const toml::node* j = r.get(t, "J", false, "", 0)) {
    def->lines["J"] = Reader::line(*j);
    def->J = r.matrix(*j, "J", nx + nu);
    check_skew(r, Reader::line(*j), def->J, "J");
  } else {
    // J = S without the port rows and columns: [[S_xx, S_xu], [S_yx, S_yu]].
    std::vector<int> keep;
    for (int i = 0; i < nx; ++i) keep.push_back(i);
    for (int i = 0; i < nu; ++i) keep.push_back(nx + nw + i);
    def->J.resize(nx + nu, nx + nu);
    for (int a = 0; a < nx + nu; ++a) {
      for (int b = 0; b < nx + nu; ++b) def->J(a, b) = def->S(keep[a], keep[b]);
    }
  }
}

// Without H the file is structure only (measured data): z, [initial] and
// [control] describe how data are generated and are refused.
void read_expressions(const Reader& r, const toml::table& t, SystemDefinition* def) {
  const toml::node* h = r.get(t, "H", false, "", 1);
  if (h == nullptr) {
    for (const char* key : {"z", "initial", "control"}) {
      if (const toml::node* n = t.get(key)) {
        r.fail(Reader::line(*n), std::string("\"") + key + "\" generates data from the energy H, "
                                 "which this file does not define; add H (the file then generates "
                                 "data) or remove " + key + " (a structure-only file for phnn import)");
      }
    }
    return;
  }
  def->lines["H"] = Reader::line(*h);
  def->energy = r.string(*h, "H");
  if (def->energy.find_first_not_of(" \t") == std::string::npos) {
    r.fail(Reader::line(*h), "\"H\" is empty; write the energy, or remove the key for a "
                             "structure-only file (measured data)");
  }
  const toml::node* z = r.get(t, "z", !def->ports.empty(),
                              " (the dissipation law, one expression per port)", 1);
  if (z != nullptr) {
    def->lines["z"] = Reader::line(*z);
    def->dissipation = r.strings(*z, "z");
    check_ports_for_z(r, Reader::line(*z), def->dissipation.size(), def->ports.size());
  }
}

}  // namespace

SystemDefinition parse_system_definition(const std::string& text, const std::string& file) {
  SystemDefinition def;
  def.file = file;
  def.text = text;
  Reader r(file, &def);
  toml::table t;
  try {
    t = toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    r.fail(static_cast<int>(e.source().begin.line),
           "not valid TOML: " + std::string(e.description()) + "; fix the syntax on this line");
  }
  for (const auto& [key, value] : t) {
    const std::string k(key.str());
    if (std::find(kTopKeys.begin(), kTopKeys.end(), k) == kTopKeys.end()) {
      const std::string near = closest_name(k, kTopKeys);
      r.fail(Reader::line(value), "unknown key \"" + k + "\"" +
                                      (near.empty() ? "" : " (did you mean \"" + near + "\"?)") +
                                      "; system files know: name, description, states, units, "
                                      "inputs, input_units, ports, H, z, S, J, [parameters], "
                                      "[initial], [control], [plots], [measurement]");
    }
  }
  const toml::node* name = r.get(t, "name", true, " (the system's name)", 1);
  def.name = r.string(*name, "name");
  def.lines["name"] = Reader::line(*name);
  if (def.name.empty()) r.fail(Reader::line(*name), "\"name\" is empty; give the system a name");
  for (char c : def.name) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.') continue;
    r.fail(Reader::line(*name), "name \"" + def.name +
                                    "\" may hold only letters, digits, '-', '_' and '.' (it names "
                                    "the system in run ids, tables and results files); e.g. "
                                    "\"coupled-duffing\"");
  }
  if (const toml::node* d = t.get("description")) def.description = r.string(*d, "description");
  read_names(r, t, &def);
  read_structure(r, t, &def);
  read_expressions(r, t, &def);
  if (def.has_energy()) {
    read_initial(r, t, &def);
    read_control(r, t, &def);
  }
  read_plots(r, t, &def);
  read_measurement(r, t, &def);
  return def;
}

}  // namespace phnn
