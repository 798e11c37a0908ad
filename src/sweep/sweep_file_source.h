// src/sweep/sweep_file_source.h — a sweep file's text, its toml++ parse, and
// the "FILE:LINE: message" errors that point into it. Internal to the parser
// (src/sweep/sweep_file*.cpp); built on toml++ (TOML_EXCEPTIONS=1, CMake).
#pragma once

#include <toml++/toml.h>

#include <string>
#include <vector>

namespace phnn {

/// The text a sweep file was parsed from, for messages: raw value text and
/// lines. Keeps a reference to `text`, which must outlive it.
class SweepSource {
 public:
  SweepSource(const std::string& file, const std::string& text);

  const std::string& file() const { return file_; }
  const std::string& text() const { return text_; }

  /// Throws SweepFileError(file(), line, message).
  [[noreturn]] void fail(int line, const std::string& message) const;

  /// Line `line` (1-based) without its line end; "" outside the file.
  std::string line_text(int line) const;
  /// Byte offset of (line, column) as toml++ counts them (column in code
  /// points, 1-based, after a UTF-8 byte-order mark); text().size() past the end.
  std::size_t offset_of(const toml::source_position& position) const;
  /// The source text of a node as written (`1e2`, `"duffng"`), line ends as spaces.
  std::string raw(const toml::node& node) const;

 private:
  std::string file_;
  const std::string& text_;
  std::vector<std::size_t> line_starts_;
};

/// "\"" + s + "\"", for messages.
std::string quoted(const std::string& s);

/// Parses the TOML of `source` with toml++. Throws SweepFileError at the line
/// of the first syntax error (invalid UTF-8 included), phrased for a sweep
/// file's author: the key concerned and the fix where one is known.
toml::table parse_sweep_toml(const SweepSource& source);

}  // namespace phnn
