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
  /// A data-set file named in `data` (sweeps/FORMAT.md): the checksum of its
  /// contents (data_set_checksum) and its number of training pairs; empty
  /// and 0 for a system file.
  std::string data_checksum = "";
  int data_train_pairs = 0;
  /// The data set comes with the text (a results file's /data, `phnn train
  /// --data`), so nothing is generated: a structure-only system file (no
  /// energy H) is accepted. False for files a sweep reads from disk.
  bool data_supplied = false;
  /// A data-set file's inference trajectories and the samples of the
  /// longest (0 for a system file).
  int data_inference = 0, data_inference_points = 0;
};

/// True for a `data` entry of a sweep file: a path ending in ".h5".
inline bool is_data_file_entry(const std::string& entry) {
  return entry.size() > 3 && entry.compare(entry.size() - 3, 3, ".h5") == 0;
}

/// Returns the system file a sweep file names (`entry` as written in
/// `systems`); throws SystemFileError (or any std::exception) when it
/// cannot. parse_sweep_file reads from disk, relative to the sweep file;
/// readers of a results file take the texts stored in it.
using SystemFileReader = std::function<SystemFileText(const std::string& entry)>;

}  // namespace phnn
