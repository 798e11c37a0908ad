// include/phnn/common/enum_names.h — one table per enum: the names of its
// values written once, and from them to_string, parse with "did you mean",
// the list of values and the error text.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "phnn/common/closest_name.h"

namespace phnn {

/// The names of an enum's values, in their documented order:
///
///   constexpr EnumNames<ModelSize, 3> kSizeNames{
///       "size", {{{ModelSize::kSmall, "small"}, {ModelSize::kMedium, "medium"},
///                 {ModelSize::kLarge, "large"}}}};
///   kSizeNames.name(ModelSize::kLarge) == "large"
///   kSizeNames.parse("lareg")  // throws std::invalid_argument:
///   // unknown size "lareg" (did you mean "large"?); expected one of: small, medium, large
template <typename T, std::size_t N>
struct EnumNames {
  struct Entry {
    T value;
    const char* name;
  };
  /// What a value is called in errors ("size", "integrator").
  const char* what;
  std::array<Entry, N> entries;

  /// The value's name; "unknown" for a value outside the table.
  std::string name(T value) const {
    for (const Entry& e : entries) {
      if (e.value == value) return e.name;
    }
    return "unknown";
  }
  /// The value named `text` (exact spelling) into *value; false if none.
  bool find(const std::string& text, T* value) const {
    for (const Entry& e : entries) {
      if (text == e.name) {
        *value = e.value;
        return true;
      }
    }
    return false;
  }
  /// The value named `text`; std::invalid_argument(unknown(text)) otherwise.
  T parse(const std::string& text) const {
    T value{};
    if (!find(text, &value)) throw std::invalid_argument(unknown(text));
    return value;
  }
  /// Every value, in table order.
  std::vector<T> all() const {
    std::vector<T> out;
    for (const Entry& e : entries) out.push_back(e.value);
    return out;
  }
  /// Every name, in table order.
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const Entry& e : entries) out.emplace_back(e.name);
    return out;
  }
  /// "small, medium, large".
  std::string list() const {
    std::string out;
    for (const Entry& e : entries) out += (out.empty() ? "" : ", ") + std::string(e.name);
    return out;
  }
  /// `unknown WHAT "text" (did you mean "NAME"?); expected one of: LIST` and
  /// `more` after the list (e.g. ", or a system file").
  std::string unknown(const std::string& text, const std::string& more = "") const {
    const std::string near = closest_name(text, names());
    return "unknown " + std::string(what) + " \"" + text + "\"" +
           (near.empty() ? "" : " (did you mean \"" + near + "\"?)") + "; expected one of: " +
           list() + more;
  }
};

}  // namespace phnn
