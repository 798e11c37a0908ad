// src/sweep/sweep_file.cpp — the sweep-file parser (format: sweeps/FORMAT.md).
//
// Two passes. parse_document() turns the text into tables of key = value
// entries (the TOML subset; syntax errors only). resolve() then maps tables
// and keys onto the defaults of docs/METHOD.md (OscillatorOptions, DatasetOptions,
// TrainerOptions, the grid axes) and checks names, types and ranges. Every
// value keeps the line it came from, so every error can name its line.
#include "phnn/sweep/sweep_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstring>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include "phnn/sweep/output_check.h"
#include "phnn/sweep/run_config.h"

namespace phnn {

SweepFileError::SweepFileError(const std::string& file, int line, const std::string& message)
    : std::invalid_argument(line > 0 ? file + ":" + std::to_string(line) + ": " + message
                                     : file + ": " + message),
      file_(file),
      line_(line),
      message_(message) {}

std::string model_key(ModelKind kind, IntegratorKind integrator) {
  return to_string(kind) + "-" + to_string(integrator);
}

std::vector<std::pair<ModelKind, IntegratorKind>> all_model_pairs() {
  return {{ModelKind::kNode, IntegratorKind::kRk2},
          {ModelKind::kPhnnJr, IntegratorKind::kDg},
          {ModelKind::kPhnnJr, IntegratorKind::kRk2},
          {ModelKind::kPhnnS, IntegratorKind::kDg},
          {ModelKind::kPhnnS, IntegratorKind::kRk2}};
}

std::vector<std::pair<ModelKind, IntegratorKind>> known_model_pairs() {
  auto pairs = all_model_pairs();
  for (ModelKind kind : {ModelKind::kNode, ModelKind::kPhnnJr, ModelKind::kPhnnS}) {
    pairs.emplace_back(kind, IntegratorKind::kRk4);
  }
  pairs.emplace_back(ModelKind::kPhnnJr, IntegratorKind::kDg4);
  pairs.emplace_back(ModelKind::kPhnnS, IntegratorKind::kDg4);
  return pairs;
}

namespace {

// ---------------------------------------------------------------------------
// Small helpers.

std::string join(const std::vector<std::string>& items, const std::string& sep = ", ") {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += sep;
    out += items[i];
  }
  return out;
}

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

// Levenshtein distance, for "did you mean" hints.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// " (did you mean "steps"?)" for the closest allowed value within 2 edits.
std::string did_you_mean(const std::string& value, const std::vector<std::string>& allowed) {
  std::size_t best = 3;
  std::string best_name;
  std::string lower = value;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const std::string& name : allowed) {
    if (name == lower) return " (did you mean " + quoted(name) + "?)";  // "PHNN-JR-DG"
  }
  for (const std::string& name : allowed) {
    const std::size_t d = edit_distance(value, name);
    if (d < best) {
      best = d;
      best_name = name;
    }
  }
  return best_name.empty() ? std::string() : " (did you mean " + quoted(best_name) + "?)";
}

// ---------------------------------------------------------------------------
// Pass 1: the TOML subset.

struct Value {
  enum class Type { kInteger, kFloat, kString, kBoolean, kArray };
  Type type = Type::kInteger;
  std::int64_t integer = 0;
  double real = 0.0;
  std::string string;
  bool boolean = false;
  std::vector<Value> items;
  std::string raw;  // source text, for messages
  int line = 0;
};

std::string type_name(Value::Type type) {
  switch (type) {
    case Value::Type::kInteger:
      return "integer";
    case Value::Type::kFloat:
      return "float";
    case Value::Type::kString:
      return "string";
    case Value::Type::kBoolean:
      return "boolean";
    case Value::Type::kArray:
      return "array";
  }
  return "value";
}

// "the string "5000"", "the float 5e4", ...
std::string describe(const Value& v) { return "the " + type_name(v.type) + " " + v.raw; }

struct Entry {
  std::string key;
  int line = 0;
  Value value;
};

struct Table {
  std::string name;  // "" for the root table; "physics.duffing" for [physics.duffing]
  int line = 0;      // line of the header (1 for the root table)
  std::vector<Entry> entries;
};

class DocumentParser {
 public:
  DocumentParser(const std::string& text, const std::string& file) : text_(text), file_(file) {}

  std::vector<Table> parse() {
    std::vector<Table> tables(1);
    tables[0].line = 1;
    for (;;) {
      skip_blank();
      skip_comment();
      if (at_end()) break;
      const char c = peek();
      if (c == '\n') {
        advance();
        continue;
      }
      if (c == '[') {
        tables.push_back(parse_header());
      } else {
        tables.back().entries.push_back(parse_entry());
      }
    }
    return tables;
  }

 private:
  [[noreturn]] void fail(int line, const std::string& message) const {
    throw SweepFileError(file_, line, message);
  }

  bool at_end() const { return pos_ >= text_.size(); }
  char peek(std::size_t ahead = 0) const {
    return pos_ + ahead < text_.size() ? text_[pos_ + ahead] : '\0';
  }
  void advance() {
    if (text_[pos_] == '\n') ++line_;
    ++pos_;
  }
  // Spaces, tabs and the '\r' of CRLF line ends.
  void skip_blank() {
    while (!at_end() && (peek() == ' ' || peek() == '\t' || peek() == '\r')) advance();
  }
  void skip_comment() {
    if (peek() != '#') return;
    while (!at_end() && peek() != '\n') advance();
  }
  // Blanks, comments and newlines (between array elements).
  void skip_blank_lines() {
    for (;;) {
      skip_blank();
      skip_comment();
      if (!at_end() && peek() == '\n') {
        advance();
      } else {
        return;
      }
    }
  }

  static bool is_bare_key_char(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  }

  // The rest of the current line, trimmed, for messages.
  std::string rest_of_line() const {
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string::npos) end = text_.size();
    std::string s = text_.substr(pos_, end - pos_);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.pop_back();
    return s;
  }

  void expect_end_of_line(const std::string& after) {
    skip_blank();
    skip_comment();
    if (at_end()) return;
    if (peek() != '\n') {
      fail(line_, "unexpected " + quoted(rest_of_line()) + " after " + after +
                      "; expected the end of the line (one key = value per line)");
    }
    advance();
  }

  std::string parse_key(const char* what) {
    const char c = peek();
    if (c == '"' || c == '\'') {
      fail(line_, std::string("quoted ") + what + "s are not supported; use a bare " + what +
                      " of letters, digits, '_' and '-'");
    }
    const std::size_t begin = pos_;
    while (!at_end() && is_bare_key_char(peek())) advance();
    if (pos_ == begin) {
      fail(line_, std::string("expected a ") + what + ", got " + quoted(rest_of_line()) +
                      "; lines are `key = value`, `[table]`, `# comment` or blank");
    }
    return text_.substr(begin, pos_ - begin);
  }

  Table parse_header() {
    Table table;
    table.line = line_;
    advance();  // '['
    if (peek() == '[') {
      fail(line_, "arrays of tables ([[...]]) are not supported; use [study.NAME] tables");
    }
    skip_blank();
    std::string name = parse_key("table name");
    for (;;) {
      skip_blank();
      if (peek() != '.') break;
      advance();
      skip_blank();
      name += "." + parse_key("table name");
    }
    if (peek() != ']') {
      fail(line_,
           "expected \"]\" to close the table header [" + name + ", got " + quoted(rest_of_line()));
    }
    advance();
    table.name = name;
    expect_end_of_line("the table header [" + name + "]");
    return table;
  }

  Entry parse_entry() {
    Entry entry;
    entry.line = line_;
    entry.key = parse_key("key");
    skip_blank();
    if (peek() == '.') {
      fail(line_, "dotted key " + quoted(entry.key + rest_of_line()) +
                      " is not supported; put the key under its [table]");
    }
    if (peek() != '=') {
      fail(line_, "expected \"=\" after key " + quoted(entry.key) + ", got " +
                      quoted(rest_of_line()) + "; write `" + entry.key + " = value`");
    }
    advance();
    skip_blank();
    if (at_end() || peek() == '\n' || peek() == '#') {
      fail(line_, "missing value for key " + quoted(entry.key));
    }
    entry.value = parse_value(entry.key);
    expect_end_of_line("the value of " + quoted(entry.key));
    return entry;
  }

  Value parse_value(const std::string& key) {
    const char c = peek();
    if (c == '"') return parse_string(key);
    if (c == '[') return parse_array(key);
    if (c == '\'') {
      fail(line_,
           "single-quoted strings are not supported (value of " + quoted(key) + "); use \"...\"");
    }
    if (c == '{') {
      fail(line_, "inline tables are not supported (value of " + quoted(key) + "); use a [table]");
    }
    return parse_scalar(key);
  }

  Value parse_string(const std::string& key) {
    Value v;
    v.type = Value::Type::kString;
    v.line = line_;
    const std::size_t begin = pos_;
    if (text_.compare(pos_, 3, "\"\"\"") == 0) {
      fail(line_, "multi-line strings (\"\"\") are not supported (value of " + quoted(key) + ")");
    }
    advance();  // opening quote
    for (;;) {
      if (at_end() || peek() == '\n') {
        fail(v.line, "unterminated string in the value of " + quoted(key) +
                         "; close it with \" on the same line");
      }
      const char c = peek();
      if (c == '"') {
        advance();
        break;
      }
      if (c == '\\') {
        advance();
        const char e = at_end() ? '\0' : peek();
        switch (e) {
          case '"':
            v.string += '"';
            break;
          case '\\':
            v.string += '\\';
            break;
          case 'n':
            v.string += '\n';
            break;
          case 't':
            v.string += '\t';
            break;
          case 'r':
            v.string += '\r';
            break;
          default:
            fail(line_, std::string("unsupported escape \"\\") + e + "\" in the value of " +
                            quoted(key) + "; allowed: \\\" \\\\ \\n \\t \\r");
        }
        advance();
        continue;
      }
      v.string += c;
      advance();
    }
    v.raw = text_.substr(begin, pos_ - begin);
    return v;
  }

  Value parse_array(const std::string& key) {
    Value v;
    v.type = Value::Type::kArray;
    v.line = line_;
    const std::size_t begin = pos_;
    advance();  // '['
    auto unterminated = [&](const std::string& detail) {
      fail(v.line, "unterminated array in the value of " + quoted(key) + ": " + detail +
                       "; close it with \"]\"");
    };
    for (;;) {
      skip_blank_lines();
      if (at_end()) unterminated("reached the end of the file");
      if (peek() == ']') {
        advance();
        break;
      }
      if (peek() == '[') {
        unterminated("found \"[\" on line " + std::to_string(line_) +
                     " (nested arrays are not supported)");
      }
      if (looks_like_key_assignment()) {
        unterminated("found " + quoted(rest_of_line()) + " on line " + std::to_string(line_));
      }
      if (peek() == ',') {
        fail(line_, "empty element in the array of " + quoted(key) +
                        " (two commas, or a "
                        "leading comma)");
      }
      v.items.push_back(parse_value(key));
      if (v.items.back().type == Value::Type::kArray) {
        fail(v.items.back().line, "nested arrays are not supported (value of " + quoted(key) + ")");
      }
      skip_blank_lines();
      if (at_end()) unterminated("reached the end of the file");
      if (peek() == ',') {
        advance();
        continue;
      }
      if (peek() == ']') {
        advance();
        break;
      }
      unterminated("expected \",\" or \"]\" after " + v.items.back().raw + ", got " +
                   quoted(rest_of_line()) + " on line " + std::to_string(line_));
    }
    v.raw = text_.substr(begin, pos_ - begin);
    // Keep messages short for arrays spanning lines.
    std::replace(v.raw.begin(), v.raw.end(), '\n', ' ');
    return v;
  }

  // At a bare word followed by '=' (the next line of a file whose array was
  // never closed).
  bool looks_like_key_assignment() const {
    std::size_t p = pos_;
    if (p >= text_.size() || !is_bare_key_char(text_[p])) return false;
    while (p < text_.size() && is_bare_key_char(text_[p])) ++p;
    while (p < text_.size() && (text_[p] == ' ' || text_[p] == '\t')) ++p;
    return p < text_.size() && text_[p] == '=';
  }

  // Digits with single underscores between them: "50_000".
  static bool digits_ok(const std::string& s, std::size_t begin, std::size_t end) {
    if (begin >= end) return false;
    for (std::size_t i = begin; i < end; ++i) {
      const char c = s[i];
      if (c == '_') {
        if (i == begin || i + 1 == end || s[i + 1] == '_') return false;
      } else if (c < '0' || c > '9') {
        return false;
      }
    }
    return true;
  }

  Value parse_scalar(const std::string& key) {
    Value v;
    v.line = line_;
    const std::size_t begin = pos_;
    while (!at_end()) {
      const char c = peek();
      if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ',' || c == ']' || c == '#')
        break;
      advance();
    }
    const std::string token = text_.substr(begin, pos_ - begin);
    v.raw = token;
    if (token == "true" || token == "false") {
      v.type = Value::Type::kBoolean;
      v.boolean = token == "true";
      return v;
    }
    // Sign, integer part, optional fraction, optional exponent (TOML).
    std::size_t i = 0;
    if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
    const std::size_t int_begin = i;
    while (i < token.size() && ((token[i] >= '0' && token[i] <= '9') || token[i] == '_')) ++i;
    bool ok = digits_ok(token, int_begin, i);
    if (ok && token[int_begin] == '0' && i - int_begin > 1) ok = false;  // leading zero
    bool is_float = false;
    if (ok && i < token.size() && token[i] == '.') {
      is_float = true;
      const std::size_t frac_begin = ++i;
      while (i < token.size() && ((token[i] >= '0' && token[i] <= '9') || token[i] == '_')) ++i;
      ok = digits_ok(token, frac_begin, i);
    }
    if (ok && i < token.size() && (token[i] == 'e' || token[i] == 'E')) {
      is_float = true;
      ++i;
      if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
      const std::size_t exp_begin = i;
      while (i < token.size() && ((token[i] >= '0' && token[i] <= '9') || token[i] == '_')) ++i;
      ok = digits_ok(token, exp_begin, i);
    }
    if (!ok || i != token.size()) {
      const bool word = !token.empty() && ((token[0] >= 'a' && token[0] <= 'z') ||
                                           (token[0] >= 'A' && token[0] <= 'Z'));
      fail(line_, "invalid value " + quoted(token) + " for key " + quoted(key) +
                      (word ? "; strings need double quotes: " + quoted(token)
                            : "; expected an integer (25), a float (1e-3, 0.14737), a \"string\", "
                              "true/false or an [array]"));
    }
    std::string digits;
    for (char c : token) {
      if (c != '_') digits += c;
    }
    errno = 0;
    if (is_float) {
      v.type = Value::Type::kFloat;
      v.real = std::strtod(digits.c_str(), nullptr);
      if (errno == ERANGE && std::abs(v.real) > 1.0) {
        fail(line_, "float " + token + " is out of range (value of " + quoted(key) + ")");
      }
    } else {
      v.type = Value::Type::kInteger;
      v.integer = std::strtoll(digits.c_str(), nullptr, 10);
      if (errno == ERANGE) {
        fail(line_, "integer " + token + " is out of range (value of " + quoted(key) + ")");
      }
    }
    return v;
  }

  const std::string& text_;
  const std::string& file_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

// ---------------------------------------------------------------------------
// Pass 2: tables and keys onto the options of docs/METHOD.md.

// Axes of [grid] or of one [study.NAME]; unset axes are inherited.
struct AxisSet {
  std::string title;
  std::optional<std::vector<SystemKind>> systems;
  std::optional<std::vector<std::pair<ModelKind, IntegratorKind>>> models;
  std::optional<std::vector<ModelSize>> sizes;
  std::optional<std::vector<int>> n_train;
  std::vector<int> n_train_lines;  // line of each n_train value
  std::optional<std::vector<Regularizer>> regularizers;
  std::optional<std::vector<int>> seeds;
};

// A key's handler: reads the entry and stores the value.
using Handler = std::function<void(const Entry&)>;

class Resolver {
 public:
  explicit Resolver(const std::string& file) : file_(file) {}

  SweepSpec resolve(const std::vector<Table>& tables) {
    SweepSpec spec;
    for (SystemKind kind : all_systems()) spec.physics[kind] = OscillatorOptions::defaults(kind);

    std::map<std::string, int> seen_tables;
    AxisSet grid;
    std::vector<std::pair<std::string, AxisSet>> studies;
    std::map<std::string, int> data_lines, training_lines;
    std::map<SystemKind, std::map<std::string, int>> physics_lines;
    std::map<SystemKind, int> physics_header;
    int data_header = 1, training_header = 1;
    bool has_name = false, has_output = false;

    for (const Table& table : tables) {
      const std::string label = "[" + table.name + "]";
      if (!table.name.empty()) {
        const auto [it, inserted] = seen_tables.emplace(table.name, table.line);
        if (!inserted) {
          fail(table.line, "duplicate table " + label + " (first defined on line " +
                               std::to_string(it->second) + "); merge the two");
        }
      }
      if (table.name.empty()) {
        apply(table, "the top level (before any [table])",
              {{"name",
                [&](const Entry& e) {
                  spec.name = get_nonempty_string(e);
                  has_name = true;
                }},
               {"output", [&](const Entry& e) {
                  spec.output = get_nonempty_string(e);
                  has_output = true;
                }}});
      } else if (table.name == "data") {
        data_header = table.line;
        data_lines = apply(table, label, data_handlers(spec.data));
      } else if (table.name == "training") {
        training_header = table.line;
        training_lines = apply(table, label, training_handlers(spec.training));
      } else if (table.name == "grid") {
        apply(table, label, axis_handlers(grid, /*allow_title=*/false));
      } else if (table.name.rfind("physics.", 0) == 0) {
        const std::string system_name = table.name.substr(8);
        const std::optional<SystemKind> kind = find_system(system_name);
        if (!kind || system_name.find('.') != std::string::npos) {
          fail(table.line, "unknown system " + quoted(system_name) + " in table " + label +
                               did_you_mean(system_name, system_names()) +
                               "; expected one of: [physics.harmonic], [physics.duffing], "
                               "[physics.self-sustained]");
        }
        physics_header[*kind] = table.line;
        physics_lines[*kind] = apply(table, label, physics_handlers(*kind, spec.physics[*kind]));
      } else if (table.name.rfind("study.", 0) == 0 && table.name.size() > 6 &&
                 table.name.find('.', 6) == std::string::npos) {
        studies.emplace_back(table.name.substr(6), AxisSet());
        apply(table, label, axis_handlers(studies.back().second, /*allow_title=*/true));
      } else {
        const std::vector<std::string> names = {"data",
                                                "training",
                                                "grid",
                                                "physics.harmonic",
                                                "physics.duffing",
                                                "physics.self-sustained",
                                                "study.NAME"};
        fail(table.line, "unknown table " + label + did_you_mean(table.name, names) +
                             "; expected one of: [data], [training], [grid], "
                             "[physics.harmonic], [physics.duffing], "
                             "[physics.self-sustained], [study.NAME]");
      }
    }

    if (!has_name) {
      fail(1, "missing required key \"name\"; add `name = \"...\"` at the top of the file");
    }
    if (!has_output) spec.output = "results/" + sanitize_file_name(spec.name) + ".h5";

    // Whole-struct constraints (e.g. energy_max >= energy_min), reported at
    // the line of the key the message names.
    validate_at([&] { spec.data.validate(); }, "[data]", data_lines, data_header);
    validate_at([&] { spec.training.validate(); }, "[training]", training_lines, training_header);
    for (SystemKind kind : all_systems()) {
      const std::string label = "[physics." + to_string(kind) + "]";
      const int header = physics_header.count(kind) ? physics_header[kind] : 1;
      validate_at(
          [&] {
            spec.physics[kind].validate();
            if (kind == SystemKind::kSelfSustained) {
              (void)Oscillator(spec.physics[kind]).self_oscillation_interval();
            }
          },
          label, physics_lines[kind], header);
    }

    // Studies: the grid's axes, overridden per study; docs/METHOD.md §6 defaults.
    if (studies.empty()) studies.emplace_back("grid", AxisSet());
    for (const auto& [name, axes] : studies) {
      StudySpec study;
      study.name = name;
      study.title = axes.title;
      study.systems = axes.systems ? *axes.systems : grid.systems ? *grid.systems : all_systems();
      study.models = axes.models ? *axes.models : grid.models ? *grid.models : all_model_pairs();
      study.sizes = axes.sizes   ? *axes.sizes
                    : grid.sizes ? *grid.sizes
                                 : std::vector<ModelSize>{ModelSize::kSmall};
      study.regularizers = axes.regularizers   ? *axes.regularizers
                           : grid.regularizers ? *grid.regularizers
                                               : std::vector<Regularizer>{Regularizer::kNone};
      if (axes.seeds) {
        study.seeds = *axes.seeds;
      } else if (grid.seeds) {
        study.seeds = *grid.seeds;
      } else {
        for (int s = 0; s < 10; ++s) study.seeds.push_back(s);
      }
      // n_train <= num_train_max: reported at the value's line.
      std::vector<int> lines;
      if (axes.n_train) {
        study.n_train = *axes.n_train;
        lines = axes.n_train_lines;
      } else if (grid.n_train) {
        study.n_train = *grid.n_train;
        lines = grid.n_train_lines;
      } else {
        study.n_train = {25};
      }
      const int max = spec.data.num_train_max;
      for (std::size_t i = 0; i < study.n_train.size(); ++i) {
        const int n = study.n_train[i];
        if (n < 1 || n > max) {
          const int line = i < lines.size()                    ? lines[i]
                           : data_lines.count("num_train_max") ? data_lines["num_train_max"]
                                                               : 1;
          fail(line, "n_train value " + std::to_string(n) +
                         (lines.empty() ? " (the default)" : "") + " of study " + quoted(name) +
                         " is outside [1, num_train_max = " + std::to_string(max) +
                         "]; lower it or raise num_train_max in [data]");
        }
      }
      spec.studies.push_back(std::move(study));
    }
    return spec;
  }

 private:
  [[noreturn]] void fail(int line, const std::string& message) const {
    throw SweepFileError(file_, line, message);
  }

  // Runs the handlers of a table; returns key -> line of the keys it set.
  std::map<std::string, int> apply(const Table& table, const std::string& label,
                                   const std::vector<std::pair<std::string, Handler>>& handlers) {
    std::map<std::string, int> lines;
    for (const Entry& e : table.entries) {
      const auto [it, inserted] = lines.emplace(e.key, e.line);
      if (!inserted) {
        fail(e.line, "duplicate key " + quoted(e.key) + " in " + label + " (first set on line " +
                         std::to_string(it->second) + "); keep one");
      }
      const auto handler = std::find_if(handlers.begin(), handlers.end(),
                                        [&](const auto& h) { return h.first == e.key; });
      if (handler == handlers.end()) {
        std::vector<std::string> allowed;
        for (const auto& h : handlers) allowed.push_back(h.first);
        fail(e.line, "unknown key " + quoted(e.key) + " in " + label +
                         did_you_mean(e.key, allowed) + "; expected one of: " + join(allowed));
      }
      handler->second(e);
    }
    return lines;
  }

  // Calls `check` (an Options::validate()); on failure rethrows its message at
  // the line of the first key of the table that the message names.
  void validate_at(const std::function<void()>& check, const std::string& label,
                   const std::map<std::string, int>& key_lines, int header_line) const {
    try {
      check();
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      int line = header_line;
      std::size_t first = std::string::npos;
      for (const auto& [key, key_line] : key_lines) {
        const std::string field = key == "seed" ? "data_seed" : key;
        for (std::size_t at = message.find(field); at != std::string::npos;
             at = message.find(field, at + 1)) {
          const bool left = at == 0 || !is_word_char(message[at - 1]);
          const bool right =
              at + field.size() == message.size() || !is_word_char(message[at + field.size()]);
          if (left && right) {
            if (at < first) {
              first = at;
              line = key_line;
            }
            break;
          }
        }
      }
      fail(line, "in " + label + ": " + message);
    }
  }

  static bool is_word_char(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  }

  // --- typed getters ------------------------------------------------------

  void expect_type(const Entry& e, const Value& v, Value::Type type,
                   const std::string& what) const {
    if (v.type != type) {
      fail(v.line, e.key + " expects " + what + ", got " + describe(v));
    }
  }

  // `what`: "an integer >= 1" or "an array of integers >= 1".
  std::int64_t get_integer(const Entry& e, const Value& v, std::int64_t min, std::int64_t max,
                           const std::string& what) const {
    expect_type(e, v, Value::Type::kInteger, what);
    if (v.integer < min || v.integer > max) {
      const bool element = &v != &e.value;
      fail(v.line,
           e.key + (element ? " value " : " = ") + v.raw + " is out of range; expected " + what);
    }
    return v.integer;
  }

  int get_int(const Entry& e, int min) const {
    return static_cast<int>(
        get_integer(e, e.value, min, INT_MAX, "an integer >= " + std::to_string(min)));
  }

  double get_number(const Entry& e, const Value& v) const {
    if (v.type == Value::Type::kInteger) return static_cast<double>(v.integer);
    expect_type(e, v, Value::Type::kFloat, "a number");
    return v.real;
  }

  std::string get_nonempty_string(const Entry& e) const {
    expect_type(e, e.value, Value::Type::kString, "a \"string\"");
    if (e.value.string.empty()) fail(e.line, e.key + " must not be empty");
    return e.value.string;
  }

  // An array of strings, non-empty and free of duplicates, each mapped by
  // `parse` (which fails with its own message).
  template <typename T>
  std::vector<T> get_string_axis(const Entry& e,
                                 const std::function<T(const Value&)>& parse) const {
    const std::vector<Value>& items = get_axis_items(e, "an array of \"strings\"");
    std::vector<T> out;
    std::set<std::string> seen;
    for (const Value& v : items) {
      expect_type(e, v, Value::Type::kString, "an array of \"strings\"");
      if (!seen.insert(v.string).second) {
        fail(v.line, e.key + " lists " + v.raw + " twice; list each value once");
      }
      out.push_back(parse(v));
    }
    return out;
  }

  const std::vector<Value>& get_axis_items(const Entry& e, const std::string& what) const {
    if (e.value.type != Value::Type::kArray) {
      fail(e.line, e.key + " expects " + what + ", got " + describe(e.value) + "; write [" +
                       e.value.raw + "]");
    }
    if (e.value.items.empty()) {
      fail(e.line, e.key + " is empty; an axis needs at least one value");
    }
    return e.value.items;
  }

  std::vector<int> get_int_axis(const Entry& e, int min, std::vector<int>* lines) const {
    const std::vector<Value>& items = get_axis_items(e, "an array of integers");
    std::vector<int> out;
    for (const Value& v : items) {
      const int n = static_cast<int>(
          get_integer(e, v, min, INT_MAX, "an array of integers >= " + std::to_string(min)));
      if (std::find(out.begin(), out.end(), n) != out.end()) {
        fail(v.line, e.key + " lists " + v.raw + " twice; list each value once");
      }
      out.push_back(n);
      if (lines) lines->push_back(v.line);
    }
    return out;
  }

  // seeds = [0, 1, 2] or seeds = "0-9".
  std::vector<int> get_seeds(const Entry& e) const {
    if (e.value.type != Value::Type::kString) return get_int_axis(e, 0, nullptr);
    const std::string& s = e.value.string;
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
      fail(e.line, "seeds range " + e.value.raw +
                       " is not \"FIRST-LAST\" with 0 <= FIRST <= LAST (at most " +
                       std::to_string(kMaxSeeds) + " seeds); write e.g. \"0-9\" or [0, 1, 2]");
    }
    std::vector<int> out;
    for (int i = std::stoi(a); i <= std::stoi(b); ++i) out.push_back(i);
    return out;
  }

  static std::vector<std::string> system_names() {
    std::vector<std::string> names;
    for (SystemKind kind : all_systems()) names.push_back(to_string(kind));
    return names;
  }

  static std::optional<SystemKind> find_system(const std::string& name) {
    for (SystemKind kind : all_systems()) {
      if (to_string(kind) == name) return kind;
    }
    return std::nullopt;
  }

  std::pair<ModelKind, IntegratorKind> parse_model_value(const Value& v) const {
    std::vector<std::string> allowed;
    for (const auto& [kind, integrator] : known_model_pairs()) {
      if (model_key(kind, integrator) == v.string) return {kind, integrator};
      allowed.push_back(model_key(kind, integrator));
    }
    const std::string expected = "; expected one of: " + join(allowed);
    const std::string& s = v.string;
    if (s == "node-dg" || s == "node-dg4") {
      fail(v.line,
           "models value " + v.raw + ": NODE has no discrete-gradient variant (it has no Hamiltonian; rk2 or rk4 only)" + expected);
    }
    const std::size_t dash = s.rfind('-');
    if (dash == std::string::npos) {
      fail(v.line, "models value " + v.raw + " is not FORMULATION-INTEGRATOR" +
                       did_you_mean(s, allowed) + expected);
    }
    const std::string formulation = s.substr(0, dash), integrator = s.substr(dash + 1);
    const bool formulation_ok =
        formulation == "node" || formulation == "phnn-jr" || formulation == "phnn-s";
    const bool integrator_ok = integrator == "rk2" || integrator == "dg" || integrator == "rk4" ||
                               integrator == "dg4";
    if (formulation_ok && !integrator_ok) {
      fail(v.line,
           "unknown integrator " + quoted(integrator) + " in models value " + v.raw + expected);
    }
    if (!formulation_ok && integrator_ok) {
      fail(v.line, "unknown formulation " + quoted(formulation) + " in models value " + v.raw +
                       did_you_mean(s, allowed) + expected);
    }
    fail(v.line, "unknown models value " + v.raw + did_you_mean(s, allowed) + expected);
  }

  // A value from a fixed list (systems, sizes, regularizers).
  template <typename T>
  T parse_enum(const Value& v, const std::string& axis, const std::vector<T>& values) const {
    std::vector<std::string> allowed;
    for (const T& t : values) {
      if (to_string(t) == v.string) return t;
      allowed.push_back(to_string(t));
    }
    fail(v.line, "unknown " + axis + " value " + v.raw + did_you_mean(v.string, allowed) +
                     "; expected one of: " + join(allowed));
  }

  // --- the tables ---------------------------------------------------------

  std::vector<std::pair<std::string, Handler>> axis_handlers(AxisSet& axes, bool allow_title) {
    std::vector<std::pair<std::string, Handler>> h;
    if (allow_title) {
      h.emplace_back("title", [this, &axes](const Entry& e) {
        expect_type(e, e.value, Value::Type::kString, "a \"string\"");
        axes.title = e.value.string;
      });
    }
    h.emplace_back("systems", [this, &axes](const Entry& e) {
      axes.systems = get_string_axis<SystemKind>(
          e, [this](const Value& v) { return parse_enum(v, "systems", all_systems()); });
    });
    h.emplace_back("models", [this, &axes](const Entry& e) {
      axes.models = get_string_axis<std::pair<ModelKind, IntegratorKind>>(
          e, [this](const Value& v) { return parse_model_value(v); });
    });
    h.emplace_back("sizes", [this, &axes](const Entry& e) {
      axes.sizes = get_string_axis<ModelSize>(e, [this](const Value& v) {
        return parse_enum(
            v, "sizes",
            std::vector<ModelSize>{ModelSize::kSmall, ModelSize::kMedium, ModelSize::kLarge});
      });
    });
    h.emplace_back("n_train", [this, &axes](const Entry& e) {
      axes.n_train_lines.clear();
      axes.n_train = get_int_axis(e, 1, &axes.n_train_lines);
    });
    h.emplace_back("regularizers", [this, &axes](const Entry& e) {
      axes.regularizers = get_string_axis<Regularizer>(e, [this](const Value& v) {
        return parse_enum(v, "regularizers",
                          std::vector<Regularizer>{Regularizer::kNone, Regularizer::kCn,
                                                   Regularizer::kSn, Regularizer::kSr});
      });
    });
    h.emplace_back("seeds", [this, &axes](const Entry& e) { axes.seeds = get_seeds(e); });
    return h;
  }

  Handler number(double& field) {
    return [this, &field](const Entry& e) { field = get_number(e, e.value); };
  }
  Handler integer(int& field, int min) {
    return [this, &field, min](const Entry& e) { field = get_int(e, min); };
  }

  std::vector<std::pair<std::string, Handler>> data_handlers(DatasetOptions& d) {
    return {{"seed",
             [this, &d](const Entry& e) {
               d.data_seed = static_cast<std::uint64_t>(
                   get_integer(e, e.value, 0, INT64_MAX, "an integer >= 0"));
             }},
            {"generation_step", number(d.generation_step)},
            {"period", number(d.period)},
            {"alpha", number(d.alpha)},
            {"beta", number(d.beta)},
            {"sample_rate", number(d.sample_rate)},
            {"energy_min", number(d.energy_min)},
            {"energy_max", number(d.energy_max)},
            {"equilibrium_energy_min", number(d.equilibrium_energy_min)},
            {"equilibrium_energy_max", number(d.equilibrium_energy_max)},
            {"num_trajectories", integer(d.num_trajectories, 1)},
            {"num_train_max", integer(d.num_train_max, 1)},
            {"num_validation", integer(d.num_validation, 1)},
            {"num_inference", integer(d.num_inference, 1)},
            {"newton_tolerance", number(d.newton.newton_tolerance)}};
  }

  std::vector<std::pair<std::string, Handler>> training_handlers(TrainerOptions& t) {
    return {{"steps", integer(t.steps, 1)},
            {"learning_rate", number(t.learning_rate)},
            {"adam_beta1", number(t.adam_beta1)},
            {"adam_beta2", number(t.adam_beta2)},
            {"adam_eps", number(t.adam_eps)},
            {"batch_size", integer(t.batch_size, 1)},
            {"eval_every", integer(t.eval_every, 1)},
            {"lambda_cn", number(t.lambda_cn)},
            {"lambda_sn", number(t.lambda_sn)},
            {"lambda_sr", number(t.lambda_sr)},
            {"jacobian_eps", number(t.jacobian_eps)},
            {"newton_tolerance", number(t.newton_tolerance)},
            {"newton_max_iterations", integer(t.newton_max_iterations, 1)},
            {"dg_min_dx_norm", number(t.dg_min_dx_norm)},
            {"divergence_norm", number(t.divergence_norm)},
            {"checkpoints", [this, &t](const Entry& e) {
               t.checkpoints = get_int_axis(e, 1, nullptr);
               std::sort(t.checkpoints.begin(), t.checkpoints.end());
             }}};
  }

  // Only the parameters the system uses (RunConfig::cell_key() hashes exactly
  // these), so a key that would be silently ignored is an error instead.
  std::vector<std::pair<std::string, Handler>> physics_handlers(SystemKind kind,
                                                                OscillatorOptions& p) {
    std::vector<std::pair<std::string, Handler>> h = {{"mass", number(p.mass)},
                                                      {"stiffness", number(p.stiffness)}};
    if (kind == SystemKind::kDuffing) h.emplace_back("cubic_stiffness", number(p.cubic_stiffness));
    if (kind != SystemKind::kSelfSustained) {
      h.emplace_back("damping", number(p.damping));
    } else {
      h.emplace_back("z_coefficients", [this, &p](const Entry& e) {
        expect_type(e, e.value, Value::Type::kArray, "an array of 3 numbers [z1, z2, z3]");
        if (e.value.items.size() != 3) {
          fail(e.line,
               "z_coefficients expects 3 numbers [z1, z2, z3] (z = z1 w + z2 w^2 + "
               "z3 w^3), got " +
                   std::to_string(e.value.items.size()));
        }
        for (int i = 0; i < 3; ++i) p.z_coefficients[i] = get_number(e, e.value.items[i]);
      });
    }
    return h;
  }

  const std::string& file_;
};

}  // namespace

SweepSpec parse_sweep_text(const std::string& text, const std::string& display_name) {
  if (text.size() > kMaxSweepFileBytes) {
    throw SweepFileError(display_name, 0, std::to_string(text.size()) + " bytes, more than the " +
                                              std::to_string(kMaxSweepFileBytes) +
                                              " a sweep file may have (its text is stored in "
                                              "the results file)");
  }
  const std::vector<Table> tables = DocumentParser(text, display_name).parse();
  SweepSpec spec = Resolver(display_name).resolve(tables);
  spec.source_path = display_name;
  spec.text = text;
  spec.text_hash = hex64(fnv1a64(text));
  return spec;
}

SweepSpec parse_sweep_file(const std::string& path) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused below.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    throw SweepFileError(path, 0,
                         "cannot open the sweep file (" + std::string(std::strerror(errno)) +
                             "); check the path (sweep files live in sweeps/, e.g. "
                             "sweeps/paper.toml)");
  }
  struct FdCloser {
    int fd;
    ~FdCloser() { ::close(fd); }
  } closer{fd};
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    throw SweepFileError(path, 0, "not a regular file (a FIFO, device, directory or socket); "
                                  "a sweep file is a text file, e.g. sweeps/paper.toml");
  }
  if (static_cast<std::uint64_t>(st.st_size) > kMaxSweepFileBytes) {
    throw SweepFileError(path, 0, std::to_string(st.st_size) + " bytes, more than the " +
                                      std::to_string(kMaxSweepFileBytes) +
                                      " a sweep file may have (its text is stored in the "
                                      "results file); use [study.*] tables and seed ranges");
  }
  std::string text(kMaxSweepFileBytes + 1, '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw SweepFileError(path, 0, "cannot read the sweep file: " + std::string(std::strerror(errno)));
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  text.resize(got);
  return parse_sweep_text(text, path);
}

}  // namespace phnn
