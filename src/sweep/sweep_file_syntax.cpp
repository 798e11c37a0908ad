// src/sweep/sweep_file_syntax.cpp — the TOML layer of the sweep-file parser:
// toml++ parses; this file owns the source text (lines, raw value text) and
// turns toml++'s parse errors into "FILE:LINE: message" SweepFileErrors that
// name the key and the fix (a file of its own: it is all about syntax errors).
#include <algorithm>
#include <cctype>
#include <string_view>

#include "phnn/sweep/sweep_file.h"
#include "sweep/sweep_file_source.h"

namespace phnn {

SweepSource::SweepSource(const std::string& file, const std::string& text)
    : file_(file), text_(text) {
  line_starts_.push_back(0);
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n') line_starts_.push_back(i + 1);
  }
}

void SweepSource::fail(int line, const std::string& message) const {
  throw SweepFileError(file_, line, message);
}

std::string SweepSource::line_text(int line) const {
  if (line < 1 || static_cast<std::size_t>(line) > line_starts_.size()) return "";
  const std::size_t begin = line_starts_[line - 1];
  std::size_t end = text_.find('\n', begin);
  if (end == std::string::npos) end = text_.size();
  if (end > begin && text_[end - 1] == '\r') --end;
  return text_.substr(begin, end - begin);
}

std::size_t SweepSource::offset_of(const toml::source_position& position) const {
  if (position.line < 1 || position.line > line_starts_.size()) return text_.size();
  std::size_t at = line_starts_[position.line - 1];
  if (position.line == 1 && text_.compare(0, 3, "\xEF\xBB\xBF") == 0) at = 3;  // BOM
  // Columns count code points: skip `column - 1` of them (UTF-8 lead bytes).
  for (toml::source_index column = 1; column < position.column && at < text_.size(); ++column) {
    ++at;
    while (at < text_.size() && (static_cast<unsigned char>(text_[at]) & 0xC0) == 0x80) ++at;
  }
  return std::min(at, text_.size());
}

std::string SweepSource::raw(const toml::node& node) const {
  const std::size_t begin = offset_of(node.source().begin);
  const std::size_t end = std::max(begin, offset_of(node.source().end));
  std::string s = text_.substr(begin, end - begin);
  std::replace(s.begin(), s.end(), '\n', ' ');
  s.erase(std::remove(s.begin(), s.end(), '\r'), s.end());
  return s;
}

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

namespace {

std::string trimmed(std::string s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && blank(s.back())) s.pop_back();
  std::size_t first = 0;
  while (first < s.size() && blank(s[first])) ++first;
  return s.substr(first);
}

// Line of the first byte that is not UTF-8 (toml++ reports the position
// before it, often on an earlier line), or 0.
int first_invalid_utf8_line(const std::string& text) {
  int line = 1;
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    const int continuation = c < 0x80                   ? 0
                             : (c >= 0xC2 && c <= 0xDF) ? 1
                             : (c >= 0xE0 && c <= 0xEF) ? 2
                             : (c >= 0xF0 && c <= 0xF4) ? 3
                                                        : -1;
    if (continuation < 0 || i + continuation >= text.size()) return line;
    for (int k = 1; k <= continuation; ++k) {
      if ((static_cast<unsigned char>(text[i + k]) & 0xC0) != 0x80) return line;
    }
    if (c == '\n') ++line;
    i += continuation + 1;
  }
  return 0;
}

// A toml++ parse error: "Error while parsing CONTEXT: DETAIL" at (line, column).
struct TomlError {
  toml::source_position position;
  std::string context;  // "key-value pair", "string", ... ("" when toml++ gives none)
  std::string detail;
};

TomlError split_error(const toml::parse_error& error) {
  TomlError e{error.source().begin, "", std::string(error.description())};
  const std::string prefix = "Error while parsing ";
  const std::size_t colon = e.detail.find(": ");
  if (e.detail.rfind(prefix, 0) == 0 && colon != std::string::npos) {
    e.context = e.detail.substr(prefix.size(), colon - prefix.size());
    e.detail = e.detail.substr(colon + 2);
  }
  return e;
}

bool starts_with(const std::string& s, const std::string& prefix) {
  return s.rfind(prefix, 0) == 0;
}

// The key a `key = value` line starts with ("" for a table header).
std::string leading_key(const std::string& line) {
  const std::string s = trimmed(line);
  if (s.empty() || s[0] == '[') return "";
  return trimmed(s.substr(0, s.find_first_of(" \t=")));
}

bool is_delimiter(char c) {
  return std::string_view(" \t\r\n[],={}#").find(c) != std::string_view::npos;
}

// The word around `at` (or ending just before it): the offending value token.
std::string token_at(const std::string& text, std::size_t at) {
  if (at >= text.size() || is_delimiter(text[at])) {
    if (at == 0 || is_delimiter(text[at - 1])) return "";
    --at;
  }
  std::size_t begin = at, end = at;
  while (begin > 0 && !is_delimiter(text[begin - 1])) --begin;
  while (end < text.size() && !is_delimiter(text[end])) ++end;
  return text.substr(begin, end - begin);
}

// From the error position to the end of its line, trimmed.
std::string rest_of_line(const SweepSource& source, const toml::source_position& position) {
  const std::size_t at = source.offset_of(position);
  const std::size_t end = std::min(source.text().find('\n', at), source.text().size());
  return trimmed(source.text().substr(at, end - at));
}

// Where a value array is still open at `end`: the line of its "[" and the key
// before it. Skips strings and comments; a "[" opens an array only after "="
// (or inside an array), otherwise it is a table header.
struct OpenArray {
  int line = 0;  // 0: no array open
  std::string key;
};

// Index just past the string that starts at `i` (at most to the end of its
// line for a one-line string, to its closing delimiter for """ and ''').
std::size_t skip_string(const std::string& text, std::size_t i, std::size_t end, int* line) {
  const char quote = text[i];
  const std::string triple(3, quote);
  if (text.compare(i, 3, triple) == 0) {
    const std::size_t close = text.find(triple, i + 3);
    const std::size_t stop = close == std::string::npos ? end : std::min(end, close + 3);
    *line += static_cast<int>(std::count(text.begin() + i, text.begin() + stop, '\n'));
    return stop;
  }
  for (++i; i < end && text[i] != '\n'; ++i) {
    if (quote == '"' && text[i] == '\\') {
      ++i;
    } else if (text[i] == quote) {
      return i + 1;
    }
  }
  return i;
}

OpenArray open_array_at(const std::string& text, std::size_t end) {
  OpenArray open;
  int depth = 0, line = 1;
  bool after_equals = false;
  for (std::size_t i = 0; i < end;) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      i = skip_string(text, i, end, &line);
      continue;
    }
    if (c == '#') {
      while (i < end && text[i] != '\n') ++i;
      continue;
    }
    if (c == '\n') {
      ++line;
      if (depth == 0) after_equals = false;
    } else if (c == '=' && depth == 0) {
      after_equals = true;
    } else if (c == '[' && (depth > 0 || after_equals)) {
      if (depth++ == 0) open.line = line;
    } else if (c == ']' && depth > 0) {
      --depth;
    }
    ++i;
  }
  if (depth == 0) return OpenArray();
  std::size_t line_begin = 0;
  for (int l = 1; l < open.line; ++l) line_begin = text.find('\n', line_begin) + 1;
  open.key = leading_key(text.substr(line_begin, text.find('\n', line_begin) - line_begin));
  return open;
}

// Line of the first dotted key or table header with more than `max_dots`
// dots (`a.b.c` outside strings and comments), or 0. toml++ nests one table
// per dot and recurses over them: a 60 kB `[a.a.a...]` needs megabytes of stack.
int first_deep_key_line(const std::string& text, int max_dots) {
  int line = 1, dots = 0;
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      const int start = line;
      i = skip_string(text, i, text.size(), &line);
      if (line != start) dots = 0;
      continue;
    }
    if (c == '.' && ++dots > max_dots) return line;
    const bool in_chain = c == '.' || c == ' ' || c == '\t' || c == '_' || c == '-' ||
                          std::isalnum(static_cast<unsigned char>(c));
    if (!in_chain) dots = 0;
    if (c == '#') {
      while (i < text.size() && text[i] != '\n') ++i;
      continue;
    }
    if (c == '\n') ++line;
    ++i;
  }
  return 0;
}

// A line that cannot continue an array: `key = ...` or a `[table]` header.
bool starts_a_new_entry(const std::string& line) {
  const std::string s = trimmed(line);
  if (s.size() > 1 && s[0] == '[')
    return std::isalpha(static_cast<unsigned char>(s[1])) || s[1] == '_';
  const std::string key = leading_key(s);
  return !key.empty() && trimmed(s.substr(key.size())).rfind('=', 0) == 0;
}

// "unterminated array ..." at the line that opened it, when toml++ stopped
// inside an array at the end of the file or on a line that starts something else.
void fail_if_unterminated_array(const SweepSource& source, const TomlError& e) {
  if (e.context != "array" && e.context != "value") return;
  const OpenArray open = open_array_at(source.text(), source.offset_of(e.position));
  if (open.line == 0) return;
  const bool at_end = e.detail.find("end-of-file") != std::string::npos;
  const std::string line = source.line_text(static_cast<int>(e.position.line));
  if (!at_end && (static_cast<int>(e.position.line) == open.line || !starts_a_new_entry(line))) {
    return;
  }
  const std::string found =
      at_end ? "reached the end of the file"
             : "found " + quoted(trimmed(line)) + " on line " + std::to_string(e.position.line);
  source.fail(open.line, "unterminated array in the value of " + quoted(open.key) + ": " + found +
                             "; close it with \"]\"");
}

// Every key named `name` in `table` and below, with its line and table label.
void find_keys(const toml::table& table, const std::string& path, const std::string& name,
               std::vector<std::pair<int, std::string>>* found) {
  for (auto&& [key, node] : table) {
    if (key.str() == name) {
      found->emplace_back(static_cast<int>(key.source().begin.line),
                          path.empty() ? "the top level" : "[" + path + "]");
    }
    if (const toml::table* sub = node.as_table()) {
      find_keys(*sub, path.empty() ? std::string(key.str()) : path + "." + std::string(key.str()),
                name, found);
    }
  }
}

// The document before line `line` (which toml++ got past without error).
toml::table parse_lines_before(const SweepSource& source, int line) {
  const std::size_t end = source.offset_of({static_cast<toml::source_index>(line), 1});
  try {
    return toml::parse(std::string_view(source.text()).substr(0, end));
  } catch (const toml::parse_error&) {
    return toml::table();
  }
}

// "cannot redefine existing ... 'NAME'": a duplicate key or table, with the
// line where it was first defined.
void fail_if_redefinition(const SweepSource& source, const TomlError& e) {
  const std::size_t open = e.detail.find('\''), close = e.detail.rfind('\'');
  if (!starts_with(e.detail, "cannot redefine existing") || open == close) return;
  const std::string name = e.detail.substr(open + 1, close - open - 1);
  const int line = static_cast<int>(e.position.line);
  const toml::table before = parse_lines_before(source, line);
  if (e.context == "table header") {
    const toml::node_view<const toml::node> first = before.at_path(name);
    const std::string where =
        first ? " (first defined on line " + std::to_string(first.node()->source().begin.line) + ")"
              : "";
    source.fail(line, "duplicate table [" + name + "]" + where + "; merge the two");
  }
  const std::string key = name.substr(name.rfind('.') + 1);
  std::vector<std::pair<int, std::string>> found;
  find_keys(before, "", key, &found);
  std::sort(found.begin(), found.end());
  while (!found.empty() && found.back().first >= line) found.pop_back();
  const std::string where = found.empty() ? ""
                                          : " in " + found.back().second + " (first set on line " +
                                                std::to_string(found.back().first) + ")";
  source.fail(line, "duplicate key " + quoted(key) + where + "; keep one");
}

// The author's phrasing of the common mistakes; toml++'s own words otherwise.
std::string explain(const SweepSource& source, const TomlError& e) {
  const std::string line = source.line_text(static_cast<int>(e.position.line));
  // Inside an array spanning lines, the key is the array's.
  const OpenArray array = open_array_at(source.text(), source.offset_of(e.position));
  const std::string key = quoted(array.line > 0 ? array.key : leading_key(line));
  const std::string rest = rest_of_line(source, e.position);
  if (e.context == "key-value pair" && starts_with(e.detail, "expected '='")) {
    return "expected \"=\" after key " + key + (rest.empty() ? "" : ", got " + quoted(rest)) +
           "; write `" + leading_key(line) +
           " = value` (lines are `key = value`, `[table]`, "
           "`# comment` or blank)";
  }
  if (e.context == "key-value pair" && starts_with(e.detail, "expected value")) {
    return "missing value for key " + key;
  }
  if (e.context == "key-value pair" && starts_with(e.detail, "expected a comment or whitespace")) {
    return "unexpected " + quoted(rest) + " after the value of " + key +
           "; expected the end of the line (one key = value per line)";
  }
  if (e.context == "table header" && starts_with(e.detail, "expected ']'")) {
    const std::string header = trimmed(
        line.substr(0, source.offset_of(e.position) - source.offset_of({e.position.line, 1})));
    return "expected \"]\" to close the table header " + header +
           (rest.empty() ? "" : ", got " + quoted(rest));
  }
  const bool at_line_end = rest.empty();
  if (e.context == "string" && at_line_end &&
      (e.detail.find("end-of-file") != std::string::npos ||
       e.detail.find("control characters") != std::string::npos)) {
    return "unterminated string in the value of " + key + "; close it with \" on the same line";
  }
  const std::string token = token_at(source.text(), source.offset_of(e.position));
  if (e.context == "value" && starts_with(e.detail, "could not determine value type")) {
    const bool word = !token.empty() && std::isalpha(static_cast<unsigned char>(token[0]));
    return "invalid value " + quoted(token) + " for key " + key +
           (word ? "; strings need double quotes: " + quoted(token)
                 : "; expected an integer (25), a float (1e-3, 0.14737), a \"string\", "
                   "true/false or an [array]");
  }
  const bool number = e.context.find("integer") != std::string::npos ||
                      e.context.find("floating-point") != std::string::npos;
  if (number && !token.empty()) {
    return "invalid value " + quoted(token) + " for key " + key + ": " + e.detail;
  }
  const bool vowel =
      !e.context.empty() && std::string_view("aeiou").find(e.context[0]) != std::string_view::npos;
  return e.detail +
         (e.context.empty()
              ? ""
              : " (while parsing " + std::string(vowel ? "an " : "a ") + e.context + ")") +
         "; the syntax is TOML 1.0, see sweeps/FORMAT.md";
}

}  // namespace

toml::table parse_sweep_toml(const SweepSource& source) {
  if (const int line = first_invalid_utf8_line(source.text())) {
    source.fail(line, "invalid UTF-8 on this line; a sweep file is UTF-8 text");
  }
  constexpr int kMaxKeyDots = 64;  // a sweep file needs 2 (physics.duffing.damping)
  if (const int line = first_deep_key_line(source.text(), kMaxKeyDots)) {
    source.fail(line, "a dotted key or table header nests more than " +
                          std::to_string(kMaxKeyDots) +
                          " tables; a sweep file needs at most "
                          "two (physics.duffing.damping = 0.5)");
  }
  try {
    return toml::parse(std::string_view(source.text()), std::string_view(source.file()));
  } catch (const toml::parse_error& error) {
    const TomlError e = split_error(error);
    fail_if_unterminated_array(source, e);
    fail_if_redefinition(source, e);
    source.fail(static_cast<int>(e.position.line), explain(source, e));
  }
}

}  // namespace phnn
