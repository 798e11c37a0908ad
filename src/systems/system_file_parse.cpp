// src/systems/system_file_parse.cpp — the TOML layer of system files:
// toml++ parses; this file turns the table into a SystemDefinition and checks
// everything that needs no expression algebra (names, sizes, S and J skew,
// designs), each problem a SystemFileError at the key's line with the fix.
// Size: one reader per part of the format, each with the checks of its keys.
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

class Reader {
 public:
  Reader(const std::string& file, SystemDefinition* def) : file_(file), def_(def) {}

  [[noreturn]] void fail(int line, const std::string& message) const {
    throw SystemFileError(file_, line, message);
  }
  static int line(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

  const toml::node* get(const toml::table& t, const std::string& key, bool required,
                        const std::string& where, int where_line) const {
    const toml::node* node = t.get(key);
    if (node == nullptr && required) {
      fail(where_line, "missing key \"" + key + "\"" + where + "; add it (sweeps/FORMAT.md, System files)");
    }
    return node;
  }
  std::string string(const toml::node& node, const std::string& key) const {
    if (!node.is_string()) fail(line(node), "\"" + key + "\" must be a string in double quotes");
    return *node.value<std::string>();
  }
  double number(const toml::node& node, const std::string& key) const {
    if (!node.is_number()) {
      fail(line(node), "\"" + key + "\" must be a number (integer or float)");
    }
    const double v = *node.value<double>();
    if (!std::isfinite(v)) fail(line(node), "\"" + key + "\" = " + std::to_string(v) + " is not finite");
    return v;
  }
  std::vector<std::string> strings(const toml::node& node, const std::string& key) const {
    const toml::array* a = node.as_array();
    if (a == nullptr) fail(line(node), "\"" + key + "\" must be an array of strings, e.g. [\"q\", \"p\"]");
    std::vector<std::string> out;
    for (const toml::node& e : *a) out.push_back(string(e, key));
    return out;
  }
  std::array<double, 2> interval(const toml::node& node, const std::string& key) const {
    const toml::array* a = node.as_array();
    if (a == nullptr || a->size() != 2) {
      fail(line(node), "\"" + key + "\" must be an interval [lo, hi]");
    }
    std::array<double, 2> out = {number(*a->get(0), key), number(*a->get(1), key)};
    if (out[0] > out[1]) {
      fail(line(node), "\"" + key + "\" = [" + num(out[0]) + ", " + num(out[1]) +
                           "] is empty (lo > hi); write it as [lo, hi] with lo <= hi");
    }
    return out;
  }
  std::vector<std::array<double, 2>> intervals(const toml::node& node, const std::string& key,
                                               std::size_t count, const std::string& of) const {
    const toml::array* a = node.as_array();
    if (a == nullptr || a->size() != count) {
      fail(line(node), "\"" + key + "\" needs " + std::to_string(count) +
                           " intervals [lo, hi], one per " + of + ", got " +
                           (a ? std::to_string(a->size()) : std::string("no array")));
    }
    std::vector<std::array<double, 2>> out;
    for (const toml::node& e : *a) out.push_back(interval(e, key));
    return out;
  }
  MatX matrix(const toml::node& node, const std::string& key, int size) const {
    const toml::array* rows = node.as_array();
    const std::string shape = std::to_string(size) + " x " + std::to_string(size);
    if (rows == nullptr || static_cast<int>(rows->size()) != size) {
      fail(line(node), "\"" + key + "\" must be a " + shape + " matrix (an array of " +
                           std::to_string(size) + " rows), got " +
                           (rows ? std::to_string(rows->size()) + " rows" : std::string("no array")));
    }
    MatX m(size, size);
    for (int i = 0; i < size; ++i) {
      const toml::node& row_node = *rows->get(static_cast<std::size_t>(i));
      const toml::array* row = row_node.as_array();
      if (row == nullptr || static_cast<int>(row->size()) != size) {
        fail(line(row_node), "row " + std::to_string(i + 1) + " of \"" + key + "\" must have " +
                                 std::to_string(size) + " numbers (a " + shape + " matrix), got " +
                                 (row ? std::to_string(row->size()) : std::string("no array")));
      }
      for (int j = 0; j < size; ++j) m(i, j) = number(*row->get(static_cast<std::size_t>(j)), key);
    }
    return m;
  }
  static std::string num(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }

 private:
  std::string file_;
  SystemDefinition* def_;
};

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

void read_initial(const Reader& r, const toml::table& t, SystemDefinition* def) {
  const toml::node* n = r.get(t, "initial", true, " (how initial states are drawn: [initial] method = "
                                                   "\"energy\" and energy = [lo, hi])", 1);
  const toml::table* it = n->as_table();
  const int line = Reader::line(*n);
  if (it == nullptr) r.fail(line, "[initial] must be a table");
  def->lines["initial"] = line;
  InitialConditionDesign& d = def->initial;
  const toml::node* method_node = r.get(*it, "method", true, " in [initial]", line);
  const std::string method = r.string(*method_node, "initial.method");
  const std::vector<std::string> methods = {"energy", "box", "algorithm1"};
  if (method == "energy") d.method = InitialConditionDesign::Method::kEnergy;
  else if (method == "box") d.method = InitialConditionDesign::Method::kBox;
  else if (method == "algorithm1") d.method = InitialConditionDesign::Method::kAlgorithm1;
  else {
    const std::string near = closest_name(method, methods);
    r.fail(Reader::line(*method_node), "unknown initial.method \"" + method + "\"" +
                     (near.empty() ? "" : " (did you mean \"" + near + "\"?)") +
                     "; expected one of: energy, box, algorithm1");
  }
  const bool needs_energy = d.method != InitialConditionDesign::Method::kBox;
  if (const toml::node* e = r.get(*it, "energy", needs_energy, " in [initial] (the interval "
                                                               "[E_min, E_max] of H(x0))", line)) {
    const auto v = r.interval(*e, "initial.energy");
    if (v[0] < 0.0) {
      r.fail(Reader::line(*e), "initial.energy = [" + Reader::num(v[0]) + ", " + Reader::num(v[1]) +
                                   "] reaches below 0; energies of initial states must be >= 0");
    }
    d.energy_min = v[0];
    d.energy_max = v[1];
    def->lines["initial.energy"] = Reader::line(*e);
  }
  if (const toml::node* b = r.get(*it, "box", d.method == InitialConditionDesign::Method::kBox,
                                  " in [initial] (one [lo, hi] per state)", line)) {
    d.box = r.intervals(*b, "initial.box", def->states.size(), "state");
  }
  if (d.method == InitialConditionDesign::Method::kAlgorithm1 && def->states.size() != 2) {
    r.fail(line, "initial.method = \"algorithm1\" is the paper's 2-state ellipse; this system has " +
                     std::to_string(def->states.size()) + " states: use \"energy\" or \"box\"");
  }
}

// [control] design = "sines" | "chirp" | "steps" (ControlDesign): inputs
// held over each sample. Every key of the table is checked.
void read_time_varying_control(const Reader& r, const toml::table& ct, int line,
                               const std::string& design, int nu, SystemDefinition* def) {
  ControlDesign* c = &def->control;
  if (nu == 0) r.fail(line, "control.design = \"" + design + "\" needs at least one input");
  const std::vector<std::string> keys =
      design == "steps" ? std::vector<std::string>{"design", "range", "hold"}
      : design == "sines" ? std::vector<std::string>{"design", "range", "frequencies", "amplitude"}
                          : std::vector<std::string>{"design", "range", "frequency", "amplitude"};
  for (const auto& [key, value] : ct) {
    const std::string k(key.str());
    if (std::find(keys.begin(), keys.end(), k) != keys.end()) continue;
    std::string known;
    for (const auto& name : keys) known += (known.empty() ? "" : ", ") + name;
    r.fail(Reader::line(value), "unknown key \"" + k + "\" in [control] for design \"" + design +
                                    "\"; it knows: " + known);
  }
  const bool need_range = design == "steps";
  if (const toml::node* range = r.get(ct, "range", need_range, " in [control] (one [lo, hi] per input)", line)) {
    c->range = r.intervals(*range, "control.range", static_cast<std::size_t>(nu), "input");
  }
  if (design == "steps") {
    c->design = ControlDesign::Design::kSteps;
    if (const toml::node* h = r.get(ct, "hold", false, "", 0)) {
      def->lines["control.hold"] = Reader::line(*h);
      c->hold = r.number(*h, "control.hold");
      if (!(c->hold > 0.0)) r.fail(Reader::line(*h), "\"control.hold\" must be > 0 (seconds per level)");
    }
    return;
  }
  c->design = design == "sines" ? ControlDesign::Design::kSines : ControlDesign::Design::kChirp;
  const toml::node* a = r.get(ct, "amplitude", true, " in [control] (an interval [lo, hi])", line);
  c->amplitude = r.interval(*a, "control.amplitude");
  const std::string fkey = design == "sines" ? "frequencies" : "frequency";
  const toml::node* f = r.get(ct, fkey, true,
                              design == "sines" ? " in [control] (a list of frequencies in Hz)"
                                                : " in [control] (an interval [f0, f1] in Hz)",
                              line);
  def->lines["control." + fkey] = Reader::line(*f);
  const toml::array* fa = f->as_array();
  constexpr std::size_t kMaxSines = 64;
  if (fa != nullptr && fa->size() > kMaxSines) {
    r.fail(Reader::line(*f), "\"control." + fkey + "\" lists " + std::to_string(fa->size()) +
                                 " frequencies; at most " + std::to_string(kMaxSines) +
                                 " sines per input are supported");
  }
  if (fa == nullptr || fa->empty() || (design == "chirp" && fa->size() != 2)) {
    r.fail(Reader::line(*f), "\"control." + fkey + "\" must be " +
                                 (design == "sines" ? "a non-empty list of frequencies in Hz"
                                                    : "[f0, f1] in Hz"));
  }
  for (const toml::node& v : *fa) {
    const double hz = r.number(v, "control." + fkey);
    if (hz < 0.0) r.fail(Reader::line(v), "\"control." + fkey + "\" must be >= 0 Hz");
    c->frequencies.push_back(hz);
  }
}

void read_control(const Reader& r, const toml::table& t, SystemDefinition* def) {
  ControlDesign& c = def->control;
  const toml::node* n = r.get(t, "control", false, "", 0);
  const int nu = static_cast<int>(def->inputs.size());
  if (n == nullptr) {
    if (nu > 0) {
      r.fail(1, "missing table [control] for " + std::to_string(nu) +
                    " input(s); add [control] design = \"constant\" and range = [[lo, hi], ...]");
    }
    return;
  }
  const toml::table* ct = n->as_table();
  const int line = Reader::line(*n);
  if (ct == nullptr) r.fail(line, "[control] must be a table");
  def->lines["control"] = line;
  const toml::node* design_node = r.get(*ct, "design", true, " in [control]", line);
  const std::string design = r.string(*design_node, "control.design");
  if (design == "constant") {
    c.design = ControlDesign::Design::kConstant;
    const toml::node* range = r.get(*ct, "range", nu > 0, " in [control] (one [lo, hi] per input)", line);
    if (range != nullptr) c.range = r.intervals(*range, "control.range", nu, "input");
  } else if (design == "energy-shaping") {
    c.design = ControlDesign::Design::kEnergyShaping;
    if (def->states.size() != 2 || nu != 1) {
      r.fail(line, "control.design = \"energy-shaping\" is the paper's Algorithm 3 for 2 states "
                   "and 1 input; use \"constant\"");
    }
    if (const toml::node* e = r.get(*ct, "energy", false, "", 0)) {
      const auto v = r.interval(*e, "control.energy");
      c.equilibrium_energy_min = v[0];
      c.equilibrium_energy_max = v[1];
      def->lines["control.energy"] = Reader::line(*e);
    }
  } else if (design == "limit-cycle") {
    c.design = ControlDesign::Design::kLimitCycle;
    if (def->ports.size() != 1 || nu != 1) {
      r.fail(line, "control.design = \"limit-cycle\" is the paper's Algorithm 4 for 1 port and 1 "
                   "input; use \"constant\"");
    }
  } else if (design == "sines" || design == "chirp" || design == "steps") {
    read_time_varying_control(r, *ct, line, design, nu, def);
  } else {
    const std::string near = closest_name(
        design, {"constant", "energy-shaping", "limit-cycle", "sines", "chirp", "steps"});
    r.fail(Reader::line(*design_node), "unknown control.design \"" + design + "\"" +
                     (near.empty() ? "" : " (did you mean \"" + near + "\"?)") +
                     "; expected one of: constant, energy-shaping, limit-cycle, sines, chirp, steps");
  }
}

// [measurement] p = "m*v" (a state from recorded columns and parameters;
// systems/measurement_map.h compiles it), ignore = ["temperature"].
void read_measurement(const Reader& r, const toml::table& t, SystemDefinition* def) {
  const toml::node* n = r.get(t, "measurement", false, "", 0);
  if (n == nullptr) return;
  const toml::table* mt = n->as_table();
  if (mt == nullptr) r.fail(Reader::line(*n), "[measurement] must be a table");
  for (const auto& [key, value] : *mt) {
    const std::string k(key.str());
    def->lines["measurement." + k] = Reader::line(value);
    if (k == "ignore") {
      def->measurement_ignore = r.strings(value, "measurement.ignore");
      continue;
    }
    if (std::find(def->states.begin(), def->states.end(), k) == def->states.end()) {
      const std::string near = closest_name(k, def->states);
      r.fail(Reader::line(value), "measurement." + k + ": \"" + k + "\" is not a state" +
                                      (near.empty() ? "" : " (did you mean \"" + near + "\"?)") +
                                      "; [measurement] computes states from recorded columns, e.g. "
                                      "p = \"m*v\", and takes ignore = [\"column\", ...]");
    }
    const std::optional<std::string> text = value.value<std::string>();
    if (!text || text->empty()) {
      r.fail(Reader::line(value), "measurement." + k + " must be an expression in quotes, e.g. "
                                  "\"m*v\" (of recorded columns and parameters)");
    }
    def->measurement.emplace_back(k, *text);
  }
}

// [plots] phase = [["q", "p"], ...] (state pairs of the phase plots);
// energies = [E1, E2] (the figure trajectories start at x = s e_1 with
// H(s e_1) = E_k, as the paper's Figures 4-6; needs H).
void read_plots(const Reader& r, const toml::table& t, SystemDefinition* def) {
  const toml::node* n = r.get(t, "plots", false, "", 0);
  if (n == nullptr) return;
  const toml::table* pt = n->as_table();
  if (pt == nullptr) r.fail(Reader::line(*n), "[plots] must be a table");
  for (const auto& [key, value] : *pt) {
    const std::string k(key.str());
    if (k == "energies") {
      const toml::array* a = value.as_array();
      if (a == nullptr || a->empty() || a->size() > 2 || !def->has_energy()) {
        r.fail(Reader::line(value), "plots.energies must be one or two energies [J] of the figure "
                                    "trajectories, e.g. [0.5, 0.75], in a file that defines H");
      }
      for (const toml::node& e : *a) {
        const double v = r.number(e, "plots.energies");
        if (!(v > 0.0)) r.fail(Reader::line(e), "plots.energies must be > 0 J");
        def->figure_energies.push_back(v);
      }
      def->lines["plots.energies"] = Reader::line(value);
    } else if (k != "phase") {
      r.fail(Reader::line(value), "unknown key plots." + k + "; [plots] knows phase and energies");
    }
  }
  const toml::node* phase = pt->get("phase");
  if (phase == nullptr) return;
  const toml::array* a = phase->as_array();
  if (a == nullptr) r.fail(Reader::line(*phase), "plots.phase must be an array of state pairs");
  for (const toml::node& e : *a) {
    const std::vector<std::string> pair = r.strings(e, "plots.phase");
    std::array<int, 2> idx = {-1, -1};
    for (std::size_t k = 0; k < pair.size() && k < 2; ++k) {
      for (std::size_t i = 0; i < def->states.size(); ++i) {
        if (def->states[i] == pair[k]) idx[k] = static_cast<int>(i);
      }
    }
    if (pair.size() != 2 || idx[0] < 0 || idx[1] < 0) {
      r.fail(Reader::line(e), "plots.phase entries must be pairs of state names, e.g. [\"" +
                                  def->states[0] + "\", \"" + def->states.back() + "\"]");
    }
    def->phase_pairs.push_back(idx);
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
