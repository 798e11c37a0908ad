// src/systems/system_file_reader.h — the typed TOML reads of system files
// (private to src/systems): each value checked for its type and range, a
// problem a SystemFileError at its line; and the readers of the design
// tables (system_file_designs.cpp) that system_file_parse.cpp calls.
#pragma once

#include <toml++/toml.h>

#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "phnn/systems/system_file.h"

namespace phnn {
namespace internal {

class SystemTomlReader {
 public:
  SystemTomlReader(const std::string& file, SystemDefinition* def) : file_(file), def_(def) {}

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

/// [initial] (required with H): how initial states are drawn.
void read_initial(const SystemTomlReader& r, const toml::table& t, SystemDefinition* def);
/// [control] (required with H and inputs): the control design.
void read_control(const SystemTomlReader& r, const toml::table& t, SystemDefinition* def);
/// [measurement] (optional): recorded columns into states.
void read_measurement(const SystemTomlReader& r, const toml::table& t, SystemDefinition* def);
/// [plots] (optional): the figure energies.
void read_plots(const SystemTomlReader& r, const toml::table& t, SystemDefinition* def);

}  // namespace internal
}  // namespace phnn
