// include/phnn/systems/system_file.h — system files: a TOML file that
// defines a port-Hamiltonian system (states, ports, parameters, the energy H
// and the dissipation law z(w) as expressions, S and J as numbers, how
// trajectories are drawn). Parsed with toml++, expressions parsed and
// differentiated with GiNaC, evaluated with muParser (sweeps/FORMAT.md,
// "System files"). Reads the file it is given; writes nothing.
#pragma once

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "phnn/systems/ph_system.h"

namespace phnn {

/// A bad system file: "FILE:LINE: what is wrong; what to do".
class SystemFileError : public std::invalid_argument {
 public:
  /// line <= 0: the error concerns the file as a whole.
  SystemFileError(const std::string& file, int line, const std::string& message);
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  std::string file_;
  int line_;
};

/// Largest system file read: a system file is a page of TOML, and its text
/// is stored as one HDF5 attribute in data and results files (an object
/// header holds at most 64 KiB of attributes).
constexpr std::size_t kMaxSystemFileBytes = 32 * 1024;

/// What a system file says, before compilation. Lines are 1-based, 0 when
/// the key is absent.
struct SystemDefinition {
  std::string file;  // path as given (messages)
  std::string text;  // the whole file
  std::string name, description;
  std::vector<std::string> states, state_units, inputs, input_units, ports;
  std::vector<std::pair<std::string, double>> parameters;  // file order
  std::string energy;                                      // H ("" = none: structure only)
  std::vector<std::string> dissipation;                    // z, one per port
  MatX S, J;
  InitialConditionDesign initial;
  ControlDesign control;
  /// Pairs of state indices for phase plots ([plots] phase = [["q","p"]]);
  /// default: consecutive pairs (0,1), (2,3), ...
  std::vector<std::array<int, 2>> phase_pairs;
  /// [plots] energies: H of the figure trajectories' initial states
  /// (PhSystem::figure_energies); empty: the first inference trajectories.
  std::vector<double> figure_energies;
  /// [measurement]: states a recording does not hold, computed from its
  /// columns (state name -> expression of recorded columns and parameters,
  /// file order), and columns a recording may hold that phnn skips.
  std::vector<std::pair<std::string, std::string>> measurement;
  std::vector<std::string> measurement_ignore;
  std::map<std::string, int> lines;  // key ("H", "S", "initial", ...) -> line
  int line_of(const std::string& key) const;
  /// False for a structure-only file (no H, z, [initial], [control]): it
  /// describes measured data (phnn import) and generates nothing.
  bool has_energy() const { return !energy.empty(); }
};

/// Parses and validates system-file text (no compilation of the
/// expressions beyond parsing and symbol checks). Throws SystemFileError.
SystemDefinition parse_system_definition(const std::string& text, const std::string& file);

/// Reads, parses, compiles and checks a system file (H at sampled initial
/// states finite and >= 0, initial conditions drawable). Throws
/// SystemFileError naming the path when it cannot be read, is not a regular
/// file or exceeds kMaxSystemFileBytes; otherwise FILE:LINE of the problem.
std::unique_ptr<PhSystem> load_system_file(const std::string& path);

/// The text of a system file, with load_system_file's checks (a regular
/// file of at most kMaxSystemFileBytes); throws SystemFileError naming it.
std::string read_system_file_text(const std::string& path);

/// The same from text already read (`file` names it in messages).
std::unique_ptr<PhSystem> compile_system(const std::string& text, const std::string& file);

}  // namespace phnn
