// src/sweep/sweep_file_values.h — reading one sweep-file value (a toml++
// node) as the type and range its key expects, with "FILE:LINE: key expects
// ..., got ..." errors and "did you mean" hints. Internal to the parser.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "phnn/config/model_config.h"
#include "phnn/config/trainer_options.h"
#include "phnn/systems/oscillators.h"
#include "sweep/sweep_file_source.h"

namespace phnn {

/// One `key = value` of a table.
struct Entry {
  std::string key;
  int line = 0;  // line of the key
  const toml::node* value = nullptr;
};

/// The entries of `table` in the order of the file (toml++ sorts them by key).
std::vector<Entry> entries_in_file_order(const toml::table& table);

/// Line of a node (toml++'s source position).
int line_of(const toml::node& node);

std::string join(const std::vector<std::string>& items);
/// The system named `name` ("duffing"), if any.
std::optional<SystemKind> find_system(const std::string& name);
/// "harmonic", "duffing", "self-sustained".
std::vector<std::string> system_names();
/// A letter, digit or '_'.
bool is_word_char(char c);
/// Position of `field` as a whole word in `message`, or npos.
std::size_t find_word(const std::string& message, const std::string& field);
/// " (did you mean "steps"?)" for the allowed value closest to `value`
/// (equal up to case, or within 2 edits), else "".
std::string did_you_mean(const std::string& value, const std::vector<std::string>& allowed);

/// Typed getters: each returns the value or fails at its line, naming the key.
class ValueReader {
 public:
  explicit ValueReader(const SweepSource& source) : source_(source) {}

  [[noreturn]] void fail(int line, const std::string& message) const {
    source_.fail(line, message);
  }
  /// "the float 1e2", "the string \"5000\"": the type and the text as written.
  std::string describe(const toml::node& value) const;

  /// `what`: "an integer >= 1" or "an array of integers >= 1" (v is e.value or an element).
  std::int64_t integer(const Entry& e, const toml::node& v, std::int64_t min, std::int64_t max,
                       const std::string& what) const;
  int int_at_least(const Entry& e, int min) const;
  /// A finite float, or an integer.
  double number(const Entry& e, const toml::node& v) const;
  std::string string(const Entry& e) const;
  std::string nonempty_string(const Entry& e) const;
  /// A table value ([name], an inline table or dotted keys); `label` is "[data]".
  const toml::table& table(const Entry& e, const std::string& label) const;

  /// Non-empty, duplicate-free axes; `lines` (optional) gets each value's line.
  std::vector<int> int_axis(const Entry& e, int min, std::vector<int>* lines) const;
  /// lambdas = [1e-6, 1e-5]: finite numbers >= 0 (integers accepted).
  std::vector<double> number_axis(const Entry& e) const;
  /// A string that must be to_string() of one of `values` (loss_norm =
  /// "mse"); the error lists them with a "did you mean" hint.
  template <typename T>
  T choice(const Entry& e, const std::vector<T>& values) const {
    std::vector<std::string> names;
    for (const T& v : values) names.push_back(to_string(v));
    return values[choice_index(e, names)];
  }
  /// Index of the string value of `e` in `allowed`; fails if it is not there.
  std::size_t choice_index(const Entry& e, const std::vector<std::string>& allowed) const;
  /// seeds = [0, 1, 2] or seeds = "0-9".
  std::vector<int> seeds(const Entry& e) const;
  /// systems = ["duffing", "systems/pendulum.toml"]: each value that is a
  /// built-in name or a system file (ends in ".toml" or contains '/') is
  /// handed to `resolve` (value, line), which returns the system's name;
  /// other values fail. Two values of one name fail.
  std::vector<std::string> systems(
      const Entry& e,
      const std::function<std::string(const std::string&, int)>& resolve) const;
  std::vector<std::pair<ModelKind, IntegratorKind>> models(const Entry& e) const;
  std::vector<ModelSize> sizes(const Entry& e) const;
  std::vector<Regularizer> regularizers(const Entry& e) const;
  /// z_coefficients = [z1, z2, z3].
  std::array<double, 3> three_numbers(const Entry& e) const;

 private:
  void expect_type(const Entry& e, const toml::node& v, toml::node_type type,
                   const std::string& what) const;
  const toml::array& axis_items(const Entry& e, const std::string& what) const;
  template <typename T, typename Parse>
  std::vector<T> string_axis(const Entry& e, const Parse& parse) const;
  template <typename T>
  T enum_value(const toml::node& v, const std::string& axis, const std::vector<T>& values) const;
  std::pair<ModelKind, IntegratorKind> model(const toml::node& v) const;

  const SweepSource& source_;
};

}  // namespace phnn
