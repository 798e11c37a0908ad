// src/apps/cli.cpp — cli::Parser on CLI11: each declaration becomes a CLI::App
// option writing into values_; what CLI11 leaves over or refuses becomes a UsageError.
#include "apps/cli.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <iterator>
#include <sstream>

#include "phnn/common/closest_name.h"

namespace phnn {
namespace cli {
namespace {

// All of `text` as a base-10 integer (CLI11's own conversion reads 010 as 8).
bool read_integer(const std::string& text, long long* value) {
  char* end = nullptr;
  errno = 0;
  *value = std::strtoll(text.c_str(), &end, 10);
  return !text.empty() && *end == '\0' && errno == 0;
}

}  // namespace

Parser::Parser(std::string command, std::string summary)
    : command_(std::move(command)),
      app_(std::make_unique<CLI::App>(summary + "\n", "phnn " + command_)) {
  app_->allow_extras();  // reported by check_parsed(), with "did you mean"
  app_->option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app_->get_formatter()->label("TEXT", "VALUE");
}

Parser::~Parser() = default;

void Parser::option(const std::string& name, const std::string& help,
                    const std::string& default_value, bool required) {
  values_[name] = default_value;
  app_->add_option("--" + name, values_[name], help)->capture_default_str()->required(required);
}

void Parser::flag(const std::string& name, const std::string& help) {
  app_->add_flag("--" + name, help);
}

void Parser::positional(const std::string& name, const std::string& help) {
  app_->add_option(name, values_[name], help)->required()->type_name("");
}

void Parser::positional_rest(const std::string& name, const std::string& help) {
  app_->add_option(name, rest_, help)->required()->type_name("");
}

bool Parser::parse(int argc, char** argv, int first) {
  // CLI11 takes the arguments from the back of the vector.
  std::vector<std::string> args(std::make_reverse_iterator(argv + argc),
                                std::make_reverse_iterator(argv + first));
  try {
    app_->parse(args);
  } catch (const CLI::CallForHelp&) {
    std::cout << app_->help();
    return false;
  } catch (const CLI::RequiredError&) {
    // Named by check_parsed(), after unknown options: "--sytem" is the fix.
  } catch (const CLI::ArgumentMismatch& e) {  // "--out: 1 required TEXT missing"
    const std::string what = e.what();
    throw usage(what.substr(0, what.find(':')) + " needs a value");
  } catch (const CLI::ParseError& e) {
    throw usage(e.what() + see_help());
  }
  check_parsed();
  return true;
}

void Parser::check_parsed() const {
  std::vector<std::string> names;
  for (const CLI::Option* o : app_->get_options()) {
    for (const std::string& name : o->get_lnames()) names.push_back("--" + name);
  }
  for (const std::string& arg : app_->remaining()) {
    if (arg == "--") continue;  // the end of options; CLI11 lists it too
    if (arg.size() < 2 || arg[0] != '-') {
      throw usage("unexpected argument \"" + arg + "\"" + see_help());
    }
    const std::string name = arg.substr(0, arg.find('=')), best = closest_name(name, names);
    throw usage("unknown option " + name + (best.empty() ? "" : " (did you mean " + best + "?)") +
                see_help());
  }
  for (const CLI::Option* o : app_->get_options()) {
    if (o->get_required() && o->count() == 0) {
      throw usage(o->get_positional()
                      ? "missing argument " + o->get_name() + see_help()
                      : o->get_name() + " is required (" + o->get_description() + ")");
    }
    const bool is_flag = o->get_expected_max() == 0;  // CLI11 takes --quiet=abc as a value
    for (const std::string& value : o->results()) {
      if (is_flag && value != "true") throw usage(o->get_name() + " takes no value");
      // "--out --quiet": CLI11 takes the next option as the value; a value that
      // names one of this command's options is a forgotten value, not a file.
      const std::string as_name = value.substr(0, value.find('='));
      if (!is_flag && !o->get_positional() &&
          std::find(names.begin(), names.end(), as_name) != names.end()) {
        throw usage(o->get_name() + " needs a value (got the option " + as_name +
                    "; a file of that name is ./" + value + ")");
      }
    }
  }
}

UsageError Parser::usage(const std::string& what) const {
  return UsageError{"phnn " + command_ + ": " + what};
}

std::string Parser::see_help() const { return "; see `phnn " + command_ + " --help`"; }

std::string Parser::get(const std::string& name) const {
  const auto it = values_.find(name);
  return it == values_.end() ? std::string() : it->second;
}

bool Parser::has(const std::string& name) const { return app_->count("--" + name) > 0; }

double Parser::get_double(const std::string& name) const {
  const std::string text = get(name);
  double v = 0;
  errno = 0;
  if (!read_number(text, &v) || errno != 0) {
    throw usage("--" + name + " = \"" + text + "\" is not a finite number");
  }
  return v;
}

std::int64_t Parser::get_int(const std::string& name) const {
  long long v = 0;
  if (!read_integer(get(name), &v)) {
    throw usage("--" + name + " = \"" + get(name) + "\" is not an integer");
  }
  return v;
}

int Parser::get_int_in(const std::string& name, int lo, int hi) const {
  const std::int64_t v = get_int(name);
  if (v < lo || v > hi) {
    throw usage("--" + name + " = " + get(name) + " is outside [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "]");
  }
  return static_cast<int>(v);
}

double Parser::get_double_in(const std::string& name, double lo, double hi) const {
  const double v = get_double(name);
  if (v < lo || v > hi) {
    std::ostringstream range;
    range << "[" << lo << ", " << hi << "]";
    throw usage("--" + name + " = " + get(name) + " is outside " + range.str());
  }
  return v;
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    out.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

bool read_number(const std::string& text, double* value) {
  char* end = nullptr;
  *value = std::strtod(text.c_str(), &end);
  return !text.empty() && *end == '\0' && std::isfinite(*value);
}

std::vector<std::int64_t> parse_int_list(const std::string& option, const std::string& text) {
  const std::string where = "--" + option + " = \"" + text + "\": ";
  const UsageError bad{where + "expected integers in [0, 2147483647] like 0-9 or 0,3,5"};
  std::vector<std::int64_t> out;
  std::stringstream parts(text);
  for (std::string part; std::getline(parts, part, ',');) {
    const std::size_t dash = part.find('-');  // none: one value, lo = hi
    long long lo = 0, hi = 0;
    if (!read_integer(part.substr(0, dash), &lo) ||
        !read_integer(dash == std::string::npos ? part : part.substr(dash + 1), &hi) || hi < lo ||
        hi > kMaxListValue) {
      throw bad;
    }
    // Counted before expanding: "0-100000000" must not allocate first.
    if (hi - lo >= static_cast<long long>(kMaxListLength - out.size())) {
      throw UsageError{where + "more than " + std::to_string(kMaxListLength) +
                       " values; write fewer (like a sweep file's seeds, e.g. 0-9)"};
    }
    for (long long v = lo; v <= hi; ++v) out.push_back(v);
  }
  if (out.empty()) throw bad;
  return out;
}

}  // namespace cli
}  // namespace phnn
