// src/apps/cli.h — a small, strict command-line parser for the subcommands:
// every option is declared with its help; unknown options, missing values and
// bad numbers exit with status 2 and a message naming the option.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace phnn {
namespace cli {

/// Exit status for bad usage (like sysexits' EX_USAGE, but the common 2).
constexpr int kUsageError = 2;

/// Thrown for bad usage; main() prints it and exits with kUsageError.
struct UsageError {
  std::string message;
};

class Parser {
 public:
  Parser(std::string command, std::string summary);

  /// Declares --name VALUE with a default ("" = required if `required`).
  void option(const std::string& name, const std::string& help,
              const std::string& default_value = "", bool required = false);
  /// Declares a boolean --name.
  void flag(const std::string& name, const std::string& help);
  /// Declares positional arguments (by name, in order).
  void positional(const std::string& name, const std::string& help);
  /// Declares that one or more further positional arguments follow the
  /// declared ones (e.g. SHARD...); read them with rest().
  void positional_rest(const std::string& name, const std::string& help);

  /// Parses argv[first..]. Returns false if --help was given (help printed).
  bool parse(int argc, char** argv, int first);

  std::string get(const std::string& name) const;
  bool has(const std::string& name) const;  // given explicitly
  bool flag_set(const std::string& name) const;
  /// The arguments of positional_rest, in order.
  const std::vector<std::string>& rest() const { return rest_values_; }
  double get_double(const std::string& name) const;
  std::int64_t get_int(const std::string& name) const;
  std::string help() const;

 private:
  struct Spec {
    std::string help;
    std::string default_value;
    bool required = false;
    bool is_flag = false;
  };
  std::string command_, summary_;
  std::map<std::string, Spec> specs_;
  std::vector<std::string> order_;
  std::vector<std::pair<std::string, std::string>> positional_specs_;
  std::map<std::string, std::string> values_;
  std::pair<std::string, std::string> rest_spec_;  // name, help; name "" = none
  std::vector<std::string> rest_values_;
};

/// Longest list parse_int_list accepts: the sweep parser's cap on seeds.
constexpr std::size_t kMaxListLength = 100000;
/// Largest value parse_int_list accepts (values become int seeds and ranks).
constexpr long long kMaxListValue = 2147483647;

/// Parses "0-9", "0,3,5" or "0-2,7" into a list of non-negative integers;
/// throws UsageError for more than kMaxListLength values (before expanding).
std::vector<std::int64_t> parse_int_list(const std::string& option,
                                         const std::string& text);

}  // namespace cli
}  // namespace phnn
