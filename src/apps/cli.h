// src/apps/cli.h — the subcommands' command lines, parsed by CLI11 (tokens,
// --name VALUE and --name=VALUE, positionals, --help). Kept on top: every
// usage error is a UsageError (exit status 2), one line naming the option and
// the fix, with "did you mean" for a misspelled option; numbers are read
// strictly (base 10, finite), ranges of integers by parse_int_list.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace CLI {
class App;
}  // namespace CLI

namespace phnn {
namespace cli {

/// `prefix + text`, or `text` if it already starts with `prefix` (an error
/// passed up through two layers says "phnn sweep: " once).
inline std::string with_prefix(const std::string& prefix, const std::string& text) {
  return text.compare(0, prefix.size(), prefix) == 0 ? text : prefix + text;
}

/// Exit status for bad usage (like sysexits' EX_USAGE, but the common 2).
constexpr int kUsageError = 2;

/// Thrown for bad usage; main() prints it and exits with kUsageError.
struct UsageError {
  std::string message;
};

/// One subcommand's options; values are read back as text by name.
///
///   cli::Parser parser("reduce", "Prints the tables of a results file.");
///   parser.positional("FILE", "results file written by `phnn sweep`");
///   parser.option("format", "markdown | latex | csv", "markdown");
///   if (!parser.parse(argc, argv, /*first=*/2)) return 0;  // --help printed
///   print_tables(parser.get("FILE"), parser.get("format"));
class Parser {
 public:
  Parser(std::string command, std::string summary);
  ~Parser();
  Parser(const Parser&) = delete;  // CLI11 holds references to values_ and rest_
  Parser& operator=(const Parser&) = delete;

  /// Declares --name VALUE with a default (shown in --help).
  void option(const std::string& name, const std::string& help,
              const std::string& default_value = "", bool required = false);
  /// Declares a boolean --name (no value: --name=1 is an error).
  void flag(const std::string& name, const std::string& help);
  /// Declares a required positional argument (by name, in order).
  void positional(const std::string& name, const std::string& help);
  /// Declares that one or more further positional arguments follow the
  /// declared ones (e.g. SHARD...); read them with rest().
  void positional_rest(const std::string& name, const std::string& help);

  /// Parses argv[first..]. Returns false if --help was given (help printed);
  /// throws UsageError for anything else that is wrong.
  bool parse(int argc, char** argv, int first);

  /// The value given, else the default ("" if none).
  std::string get(const std::string& name) const;
  bool has(const std::string& name) const;  // given explicitly
  bool flag_set(const std::string& name) const { return has(name); }
  /// The arguments of positional_rest, in order.
  const std::vector<std::string>& rest() const { return rest_; }
  double get_double(const std::string& name) const;     // finite
  std::int64_t get_int(const std::string& name) const;  // base 10
  /// get_int within [lo, hi] (a C++ int), or a UsageError naming the range.
  int get_int_in(const std::string& name, int lo, int hi) const;
  /// get_double within [lo, hi], or a UsageError naming the range.
  double get_double_in(const std::string& name, double lo, double hi) const;

 private:
  UsageError usage(const std::string& what) const;  // "phnn COMMAND: what"
  std::string see_help() const;                     // "; see `phnn COMMAND --help`"
  void check_parsed() const;  // unknown options, missing arguments, flags' values

  std::string command_;
  std::unique_ptr<CLI::App> app_;
  std::map<std::string, std::string> values_;  // CLI11 writes the values here
  std::vector<std::string> rest_;
};

/// Longest list parse_int_list accepts: the sweep parser's cap on seeds.
constexpr std::size_t kMaxListLength = 100000;
/// Largest value parse_int_list accepts (values become int seeds and ranks).
constexpr long long kMaxListValue = 2147483647;

/// The comma-separated items of `text`, empty ones kept ("a,,b" -> a, "", b).
std::vector<std::string> split_commas(const std::string& text);

/// All of `text` as a finite double (strtod; sets errno as strtod does).
bool read_number(const std::string& text, double* value);

/// Parses "0-9", "0,3,5" or "0-2,7" into a list of non-negative integers;
/// throws UsageError for more than kMaxListLength values (before expanding).
std::vector<std::int64_t> parse_int_list(const std::string& option, const std::string& text);

}  // namespace cli
}  // namespace phnn
