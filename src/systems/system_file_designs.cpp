// src/systems/system_file_designs.cpp — the design tables of a system file
// ([initial], [control], [measurement], [plots]) read into its
// SystemDefinition, each problem a SystemFileError at the key's line with
// the fix (system_file_reader.h). Touches no file.
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
namespace internal {

using Reader = SystemTomlReader;

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
  if (!InitialConditionDesign::kMethodNames.find(method, &d.method)) {
    r.fail(Reader::line(*method_node), InitialConditionDesign::kMethodNames.unknown(method));
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

namespace {

// [control] design = "sines" | "chirp" | "steps" (ControlDesign, already
// read into def->control.design; `design` its name): inputs held over each
// sample. Every key of the table is checked.
void read_time_varying_control(const Reader& r, const toml::table& ct, int line,
                               const std::string& design, int nu, SystemDefinition* def) {
  using Design = ControlDesign::Design;
  ControlDesign* c = &def->control;
  const bool steps = c->design == Design::kSteps, sines = c->design == Design::kSines;
  if (nu == 0) r.fail(line, "control.design = \"" + design + "\" needs at least one input");
  const std::vector<std::string> keys =
      steps   ? std::vector<std::string>{"design", "range", "hold"}
      : sines ? std::vector<std::string>{"design", "range", "frequencies", "amplitude"}
              : std::vector<std::string>{"design", "range", "frequency", "amplitude"};
  for (const auto& [key, value] : ct) {
    const std::string k(key.str());
    if (std::find(keys.begin(), keys.end(), k) != keys.end()) continue;
    std::string known;
    for (const auto& name : keys) known += (known.empty() ? "" : ", ") + name;
    r.fail(Reader::line(value), "unknown key \"" + k + "\" in [control] for design \"" + design +
                                    "\"; it knows: " + known);
  }
  if (const toml::node* range = r.get(ct, "range", steps, " in [control] (one [lo, hi] per input)", line)) {
    c->range = r.intervals(*range, "control.range", static_cast<std::size_t>(nu), "input");
  }
  if (steps) {
    if (const toml::node* h = r.get(ct, "hold", false, "", 0)) {
      def->lines["control.hold"] = Reader::line(*h);
      c->hold = r.number(*h, "control.hold");
      if (!(c->hold > 0.0)) r.fail(Reader::line(*h), "\"control.hold\" must be > 0 (seconds per level)");
    }
    return;
  }
  const toml::node* a = r.get(ct, "amplitude", true, " in [control] (an interval [lo, hi])", line);
  c->amplitude = r.interval(*a, "control.amplitude");
  const std::string fkey = sines ? "frequencies" : "frequency";
  const toml::node* f = r.get(ct, fkey, true,
                              sines ? " in [control] (a list of frequencies in Hz)"
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
  if (fa == nullptr || fa->empty() || (!sines && fa->size() != 2)) {
    r.fail(Reader::line(*f), "\"control." + fkey + "\" must be " +
                                 (sines ? "a non-empty list of frequencies in Hz" : "[f0, f1] in Hz"));
  }
  for (const toml::node& v : *fa) {
    const double hz = r.number(v, "control." + fkey);
    if (hz < 0.0) r.fail(Reader::line(v), "\"control." + fkey + "\" must be >= 0 Hz");
    c->frequencies.push_back(hz);
  }
}

}  // namespace

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
  if (!ControlDesign::kDesignNames.find(design, &c.design)) {
    r.fail(Reader::line(*design_node), ControlDesign::kDesignNames.unknown(design));
  }
  using Design = ControlDesign::Design;
  if (c.design == Design::kConstant) {
    const toml::node* range = r.get(*ct, "range", nu > 0, " in [control] (one [lo, hi] per input)", line);
    if (range != nullptr) c.range = r.intervals(*range, "control.range", nu, "input");
  } else if (c.design == Design::kEnergyShaping) {
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
  } else if (c.design == Design::kLimitCycle) {
    if (def->ports.size() != 1 || nu != 1) {
      r.fail(line, "control.design = \"limit-cycle\" is the paper's Algorithm 4 for 1 port and 1 "
                   "input; use \"constant\"");
    }
  } else {  // sines, chirp, steps
    read_time_varying_control(r, *ct, line, design, nu, def);
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

}  // namespace internal
}  // namespace phnn
