// include/phnn/config/system_file_text.h — how the text of a system file a
// sweep names is found: on disk (relative to the sweep file) or in a results
// file that stored it. Shared by the sweep-file parser and the results file.
#pragma once

#include <functional>
#include <string>

namespace phnn {

/// A system file's text and the name its errors show (its path as opened,
/// or where in a results file it was stored).
struct SystemFileText {
  std::string shown_as, text;
};

/// Returns the system file a sweep file names (`entry` as written in
/// `systems`); throws SystemFileError (or any std::exception) when it
/// cannot. parse_sweep_file reads from disk, relative to the sweep file;
/// readers of a results file take the texts stored in it.
using SystemFileReader = std::function<SystemFileText(const std::string& entry)>;

}  // namespace phnn
