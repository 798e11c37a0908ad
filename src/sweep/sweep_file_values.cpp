// src/sweep/sweep_file_values.cpp — one sweep-file value as the type and
// range its key expects: numbers, strings, fixed-choice strings, the grid
// axes (systems, models, sizes, n_train, regularizers, seeds, lambdas), with
// the line and the allowed values in every error (split from the table walk:
// this file knows values, not keys).
#include "sweep/sweep_file_values.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <set>

#include "phnn/common/closest_name.h"
#include "phnn/integrators/integrator.h"
#include "phnn/sweep/sweep_file.h"
#include "phnn/systems/ph_system.h"

namespace phnn {

std::vector<Entry> entries_in_file_order(const toml::table& table) {
  std::vector<Entry> entries;
  std::vector<toml::source_position> positions;
  for (auto&& [key, node] : table) {
    entries.push_back(
        Entry{std::string(key.str()), static_cast<int>(key.source().begin.line), &node});
    positions.push_back(key.source().begin);
  }
  std::vector<std::size_t> order(entries.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return positions[a] < positions[b]; });
  std::vector<Entry> sorted;
  for (std::size_t i : order) sorted.push_back(entries[i]);
  return sorted;
}

int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i > 0 ? ", " : "") + items[i];
  return out;
}

namespace {

std::string type_name(const toml::node& v) {
  switch (v.type()) {
    case toml::node_type::integer:
      return "integer";
    case toml::node_type::floating_point:
      return "float";
    case toml::node_type::string:
      return "string";
    case toml::node_type::boolean:
      return "boolean";
    case toml::node_type::array:
      return "array";
    case toml::node_type::table:
      return "table";
    case toml::node_type::date:
      return "date";
    case toml::node_type::time:
      return "time";
    case toml::node_type::date_time:
      return "date-time";
    default:
      return "value";
  }
}

}  // namespace

bool is_word_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
}

// Position of `field` as a whole word in `message`, or npos.
std::size_t find_word(const std::string& message, const std::string& field) {
  for (std::size_t at = message.find(field); at != std::string::npos;
       at = message.find(field, at + 1)) {
    const bool left = at == 0 || !is_word_char(message[at - 1]);
    const std::size_t end = at + field.size();
    if (left && (end == message.size() || !is_word_char(message[end]))) return at;
  }
  return std::string::npos;
}

std::optional<SystemKind> find_system(const std::string& name) {
  for (SystemKind kind : all_systems()) {
    if (to_string(kind) == name) return kind;
  }
  return std::nullopt;
}

std::vector<std::string> system_names() {
  std::vector<std::string> names;
  for (SystemKind kind : all_systems()) names.push_back(to_string(kind));
  return names;
}

std::string did_you_mean(const std::string& value, const std::vector<std::string>& allowed) {
  const std::string name = closest_name(value, allowed);
  return name.empty() ? std::string() : " (did you mean " + quoted(name) + "?)";
}

std::string ValueReader::describe(const toml::node& v) const {
  if (const toml::table* t = v.as_table(); t && !t->is_inline()) return "a [table]";
  if (const toml::array* a = v.as_array(); a && a->is_array_of_tables()) {
    return "an array of tables ([[...]])";
  }
  return "the " + type_name(v) + " " + source_.raw(v);
}

void ValueReader::expect_type(const Entry& e, const toml::node& v, toml::node_type type,
                              const std::string& what) const {
  if (v.type() != type) fail(line_of(v), e.key + " expects " + what + ", got " + describe(v));
}

std::int64_t ValueReader::integer(const Entry& e, const toml::node& v, std::int64_t min,
                                  std::int64_t max, const std::string& what) const {
  expect_type(e, v, toml::node_type::integer, what);
  const std::int64_t n = v.as_integer()->get();
  if (n < min || n > max) {
    const bool element = &v != e.value;
    fail(line_of(v), e.key + (element ? " value " : " = ") + source_.raw(v) +
                         " is out of range; expected " + what);
  }
  return n;
}

int ValueReader::int_at_least(const Entry& e, int min) const {
  return static_cast<int>(
      integer(e, *e.value, min, INT_MAX, "an integer >= " + std::to_string(min)));
}

double ValueReader::number(const Entry& e, const toml::node& v) const {
  if (const auto* n = v.as_integer()) return static_cast<double>(n->get());
  expect_type(e, v, toml::node_type::floating_point, "a number");
  const double x = v.as_floating_point()->get();
  if (!std::isfinite(x)) {
    fail(line_of(v), e.key + " expects a finite number, got " + describe(v));
  }
  return x;
}

std::string ValueReader::string(const Entry& e) const {
  expect_type(e, *e.value, toml::node_type::string, "a \"string\"");
  return e.value->as_string()->get();
}

std::string ValueReader::nonempty_string(const Entry& e) const {
  const std::string s = string(e);
  if (s.empty()) fail(e.line, e.key + " must not be empty");
  return s;
}

const toml::table& ValueReader::table(const Entry& e, const std::string& label) const {
  if (const toml::table* t = e.value->as_table()) return *t;
  fail(line_of(*e.value), e.key + " must be the table " + label + ", got " + describe(*e.value) +
                              "; write " + label + " on a line of its own, its keys below it");
}

const toml::array& ValueReader::axis_items(const Entry& e, const std::string& what) const {
  const toml::array* items = e.value->as_array();
  if (!items) {
    fail(e.line, e.key + " expects " + what + ", got " + describe(*e.value) + "; write [" +
                     source_.raw(*e.value) + "]");
  }
  if (items->empty()) fail(e.line, e.key + " is empty; an axis needs at least one value");
  return *items;
}

std::vector<int> ValueReader::int_axis(const Entry& e, int min, std::vector<int>* lines) const {
  std::vector<int> out;
  for (const toml::node& v : axis_items(e, "an array of integers")) {
    const int n = static_cast<int>(
        integer(e, v, min, INT_MAX, "an array of integers >= " + std::to_string(min)));
    if (std::find(out.begin(), out.end(), n) != out.end()) {
      fail(line_of(v), e.key + " lists " + source_.raw(v) + " twice; list each value once");
    }
    out.push_back(n);
    if (lines) lines->push_back(line_of(v));
  }
  return out;
}

std::vector<double> ValueReader::number_axis(const Entry& e) const {
  std::vector<double> out;
  for (const toml::node& v : axis_items(e, "an array of numbers")) {
    const double x = number(e, v);
    if (!(x >= 0.0)) {
      fail(line_of(v), e.key + " value " + source_.raw(v) +
                           " is out of range; expected an array of numbers >= 0");
    }
    if (std::find(out.begin(), out.end(), x) != out.end()) {
      fail(line_of(v), e.key + " lists " + source_.raw(v) + " twice; list each value once");
    }
    out.push_back(x);
  }
  return out;
}

std::size_t ValueReader::choice_index(const Entry& e,
                                      const std::vector<std::string>& allowed) const {
  const std::string s = string(e);
  const auto it = std::find(allowed.begin(), allowed.end(), s);
  if (it == allowed.end()) {
    fail(e.line, "unknown " + e.key + " " + source_.raw(*e.value) + did_you_mean(s, allowed) +
                     "; expected one of: " + join(allowed));
  }
  return static_cast<std::size_t>(it - allowed.begin());
}

std::vector<int> ValueReader::seeds(const Entry& e) const {
  const auto* text = e.value->as_string();
  if (!text) return int_axis(e, 0, nullptr);
  const std::string& s = text->get();
  const std::size_t dash = s.find('-');
  const auto all_digits = [](const std::string& t) {
    return !t.empty() && t.size() <= 9 &&
           std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  const std::string a = dash == std::string::npos ? "" : s.substr(0, dash);
  const std::string b = dash == std::string::npos ? "" : s.substr(dash + 1);
  constexpr int kMaxSeeds = 100000;
  if (!all_digits(a) || !all_digits(b) || std::stoi(a) > std::stoi(b) ||
      std::stoi(b) - std::stoi(a) >= kMaxSeeds) {
    fail(e.line, "seeds range " + source_.raw(*e.value) +
                     " is not \"FIRST-LAST\" with 0 <= FIRST <= LAST (at most " +
                     std::to_string(kMaxSeeds) + " seeds); write e.g. \"0-9\" or [0, 1, 2]");
  }
  std::vector<int> out;
  for (int i = std::stoi(a); i <= std::stoi(b); ++i) out.push_back(i);
  return out;
}

// An array of strings, non-empty and free of duplicates, each mapped by
// `parse` (which fails with its own message).
template <typename T, typename Parse>
std::vector<T> ValueReader::string_axis(const Entry& e, const Parse& parse) const {
  std::vector<T> out;
  std::set<std::string> seen;
  for (const toml::node& v : axis_items(e, "an array of \"strings\"")) {
    expect_type(e, v, toml::node_type::string, "an array of \"strings\"");
    if (!seen.insert(v.as_string()->get()).second) {
      fail(line_of(v), e.key + " lists " + source_.raw(v) + " twice; list each value once");
    }
    out.push_back(parse(v));
  }
  return out;
}

// A value from a fixed list (systems, sizes, regularizers).
template <typename T>
T ValueReader::enum_value(const toml::node& v, const std::string& axis,
                          const std::vector<T>& values) const {
  const std::string& s = v.as_string()->get();
  std::vector<std::string> allowed;
  for (const T& t : values) {
    if (to_string(t) == s) return t;
    allowed.push_back(to_string(t));
  }
  fail(line_of(v), "unknown " + axis + " value " + source_.raw(v) + did_you_mean(s, allowed) +
                       "; expected one of: " + join(allowed));
}

std::vector<std::string> ValueReader::systems(
    const Entry& e, const std::function<std::string(const std::string&, int)>& resolve) const {
  std::vector<int> lines;
  std::vector<std::string> names = string_axis<std::string>(e, [&](const toml::node& v) {
    const std::string& s = v.as_string()->get();
    lines.push_back(line_of(v));
    if (is_system_file_argument(s) || find_system(s)) return resolve(s, line_of(v));
    fail(line_of(v), "unknown systems value " + source_.raw(v) + did_you_mean(s, system_names()) +
                         "; expected one of: " + join(system_names()) +
                         ", the name of a shipped system file (in " + shipped_systems_dir() +
                         "), or a system file (a path ending in .toml, relative to this file; "
                         "sweeps/FORMAT.md, \"System files\")");
  });
  for (std::size_t i = 0; i < names.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (names[i] == names[j]) {
        fail(lines[i], "systems lists two systems named " + quoted(names[i]) +
                           "; list each system once (a system file's name is its `name` key)");
      }
    }
  }
  return names;
}

std::vector<ModelSize> ValueReader::sizes(const Entry& e) const {
  const std::vector<ModelSize> all = {ModelSize::kSmall, ModelSize::kMedium, ModelSize::kLarge};
  return string_axis<ModelSize>(e,
                                [&](const toml::node& v) { return enum_value(v, "sizes", all); });
}

std::vector<Regularizer> ValueReader::regularizers(const Entry& e) const {
  const std::vector<Regularizer> all = {Regularizer::kNone, Regularizer::kCn, Regularizer::kSn,
                                        Regularizer::kSr};
  return string_axis<Regularizer>(
      e, [&](const toml::node& v) { return enum_value(v, "regularizers", all); });
}

std::vector<std::pair<ModelKind, IntegratorKind>> ValueReader::models(const Entry& e) const {
  return string_axis<std::pair<ModelKind, IntegratorKind>>(
      e, [this](const toml::node& v) { return model(v); });
}

std::pair<ModelKind, IntegratorKind> ValueReader::model(const toml::node& v) const {
  const std::string& s = v.as_string()->get();
  const std::string raw = source_.raw(v);
  std::vector<std::string> allowed;
  for (const auto& [kind, integrator] : known_model_pairs()) {
    if (model_key(kind, integrator) == s) return {kind, integrator};
    allowed.push_back(model_key(kind, integrator));
  }
  const std::string expected = "; expected one of: " + join(allowed);
  const std::size_t dash = s.rfind('-');
  if (dash == std::string::npos) {
    fail(line_of(v), "models value " + raw + " is not FORMULATION-INTEGRATOR" +
                         did_you_mean(s, allowed) + expected);
  }
  const std::string formulation = s.substr(0, dash), integrator = s.substr(dash + 1);
  ModelKind model_kind{};
  IntegratorKind integrator_kind{};
  const bool formulation_ok = kModelNames.find(formulation, &model_kind);
  const bool integrator_ok = kIntegratorNames.find(integrator, &integrator_kind);
  if (formulation_ok && integrator_ok && model_kind == ModelKind::kNode &&
      is_discrete_gradient(integrator_kind)) {
    std::string explicit_names;
    for (const Integrator& in : all_integrators()) {
      if (in.discrete_gradient) continue;
      explicit_names += (explicit_names.empty() ? "" : " or ") + to_string(in.kind);
    }
    fail(line_of(v), "models value " + raw +
                         ": NODE has no discrete-gradient variant (it has no "
                         "Hamiltonian; " +
                         explicit_names + " only)" + expected);
  }
  if (formulation_ok && !integrator_ok) {
    fail(line_of(v),
         "unknown integrator " + quoted(integrator) + " in models value " + raw + expected);
  }
  if (!formulation_ok && integrator_ok) {
    fail(line_of(v), "unknown formulation " + quoted(formulation) + " in models value " + raw +
                         did_you_mean(s, allowed) + expected);
  }
  fail(line_of(v), "unknown models value " + raw + did_you_mean(s, allowed) + expected);
}

std::array<double, 3> ValueReader::three_numbers(const Entry& e) const {
  expect_type(e, *e.value, toml::node_type::array, "an array of 3 numbers [z1, z2, z3]");
  const toml::array& items = *e.value->as_array();
  if (items.size() != 3) {
    fail(e.line, e.key + " expects 3 numbers [z1, z2, z3] (z = z1 w + z2 w^2 + z3 w^3), got " +
                     std::to_string(items.size()));
  }
  std::array<double, 3> out{};
  for (std::size_t i = 0; i < 3; ++i) out[i] = number(e, items[i]);
  return out;
}

}  // namespace phnn
