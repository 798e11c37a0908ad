// src/apps/cli.cpp
#include "apps/cli.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace phnn {
namespace cli {

Parser::Parser(std::string command, std::string summary)
    : command_(std::move(command)), summary_(std::move(summary)) {}

void Parser::option(const std::string& name, const std::string& help,
                    const std::string& default_value, bool required) {
  specs_[name] = Spec{help, default_value, required, false};
  order_.push_back(name);
}

void Parser::flag(const std::string& name, const std::string& help) {
  specs_[name] = Spec{help, "", false, true};
  order_.push_back(name);
}

void Parser::positional(const std::string& name, const std::string& help) {
  positional_specs_.emplace_back(name, help);
}

void Parser::positional_rest(const std::string& name, const std::string& help) {
  rest_spec_ = {name, help};
}

std::string Parser::help() const {
  std::ostringstream out;
  out << "usage: phnn " << command_;
  for (const auto& p : positional_specs_) out << " " << p.first;
  if (!rest_spec_.first.empty()) out << " " << rest_spec_.first << "...";
  out << " [options]\n\n" << summary_ << "\n\n";
  for (const auto& p : positional_specs_) {
    out << "  " << p.first << "\n      " << p.second << "\n";
  }
  if (!rest_spec_.first.empty()) {
    out << "  " << rest_spec_.first << "...\n      " << rest_spec_.second << "\n";
  }
  for (const auto& name : order_) {
    const Spec& s = specs_.at(name);
    out << "  --" << name << (s.is_flag ? "" : " VALUE") << "\n      " << s.help;
    if (s.required) out << " (required)";
    else if (!s.is_flag && !s.default_value.empty())
      out << " (default: " << s.default_value << ")";
    out << "\n";
  }
  out << "  --help\n      print this help\n";
  return out.str();
}

bool Parser::parse(int argc, char** argv, int first) {
  std::size_t next_positional = 0;
  for (int i = first; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << help();
      return false;
    }
    if (arg.rfind("--", 0) == 0) {
      std::string name = arg.substr(2), value;
      const auto eq = name.find('=');
      bool has_inline = false;
      if (eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        has_inline = true;
      }
      auto it = specs_.find(name);
      if (it == specs_.end()) {
        throw UsageError{"phnn " + command_ + ": unknown option --" + name +
                         "; see `phnn " + command_ + " --help`"};
      }
      if (it->second.is_flag) {
        if (has_inline) {
          throw UsageError{"phnn " + command_ + ": --" + name + " takes no value"};
        }
        values_[name] = "1";
        continue;
      }
      if (!has_inline) {
        if (i + 1 >= argc) {
          throw UsageError{"phnn " + command_ + ": --" + name + " needs a value"};
        }
        value = argv[++i];
      }
      values_[name] = value;
    } else if (next_positional >= positional_specs_.size() && !rest_spec_.first.empty()) {
      rest_values_.push_back(arg);
    } else {
      if (next_positional >= positional_specs_.size()) {
        throw UsageError{"phnn " + command_ + ": unexpected argument \"" + arg +
                         "\"; see `phnn " + command_ + " --help`"};
      }
      values_[positional_specs_[next_positional++].first] = arg;
    }
  }
  if (next_positional < positional_specs_.size()) {
    throw UsageError{"phnn " + command_ + ": missing argument " +
                     positional_specs_[next_positional].first + "; see `phnn " +
                     command_ + " --help`"};
  }
  if (!rest_spec_.first.empty() && rest_values_.empty()) {
    throw UsageError{"phnn " + command_ + ": missing argument " + rest_spec_.first + "; see `phnn " +
                     command_ + " --help`"};
  }
  for (const auto& [name, spec] : specs_) {
    if (spec.required && !values_.count(name)) {
      throw UsageError{"phnn " + command_ + ": --" + name + " is required (" +
                       spec.help + ")"};
    }
  }
  return true;
}

std::string Parser::get(const std::string& name) const {
  auto it = values_.find(name);
  if (it != values_.end()) return it->second;
  auto spec = specs_.find(name);
  return spec == specs_.end() ? std::string() : spec->second.default_value;
}

bool Parser::has(const std::string& name) const { return values_.count(name) > 0; }

bool Parser::flag_set(const std::string& name) const { return values_.count(name) > 0; }

double Parser::get_double(const std::string& name) const {
  const std::string text = get(name);
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(v)) {
    throw UsageError{"phnn " + command_ + ": --" + name + " = \"" + text +
                     "\" is not a finite number"};
  }
  return v;
}

std::int64_t Parser::get_int(const std::string& name) const {
  const std::string text = get(name);
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0) {
    throw UsageError{"phnn " + command_ + ": --" + name + " = \"" + text +
                     "\" is not an integer"};
  }
  return v;
}

std::vector<std::int64_t> parse_int_list(const std::string& option,
                                         const std::string& text) {
  std::vector<std::int64_t> out;
  std::stringstream ss(text);
  std::string part;
  auto bad = [&]() {
    return UsageError{"--" + option + " = \"" + text +
                      "\": expected integers in [0, 2147483647] like 0-9 or 0,3,5"};
  };
  auto too_long = [&]() {
    return UsageError{"--" + option + " = \"" + text + "\": more than " +
                      std::to_string(kMaxListLength) +
                      " values; write fewer (like a sweep file's seeds, e.g. 0-9)"};
  };
  while (std::getline(ss, part, ',')) {
    const auto dash = part.find('-');
    char* end = nullptr;
    if (dash == std::string::npos) {
      const long long v = std::strtoll(part.c_str(), &end, 10);
      if (part.empty() || *end != '\0' || v < 0 || v > kMaxListValue) throw bad();
      if (out.size() >= kMaxListLength) throw too_long();
      out.push_back(v);
    } else {
      const std::string a = part.substr(0, dash), b = part.substr(dash + 1);
      const long long lo = std::strtoll(a.c_str(), &end, 10);
      if (a.empty() || *end != '\0') throw bad();
      const long long hi = std::strtoll(b.c_str(), &end, 10);
      if (b.empty() || *end != '\0' || lo < 0 || hi < lo || hi > kMaxListValue) throw bad();
      // Counted before expanding: "0-100000000" must not allocate first.
      if (hi - lo >= static_cast<long long>(kMaxListLength - out.size())) throw too_long();
      for (long long v = lo; v <= hi; ++v) out.push_back(v);
    }
  }
  if (out.empty()) throw bad();
  return out;
}

}  // namespace cli
}  // namespace phnn
