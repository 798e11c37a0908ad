// include/phnn/store/results_file.h — the one parallel-HDF5 file that holds
// every run of a sweep (layout: docs/RESULTS_FORMAT.md).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "phnn/config/run_config.h"
#include "phnn/config/run_result.h"
#include "phnn/config/system_file_text.h"
#include "phnn/data/ph_dataset.h"

namespace phnn {

/// Fixed per-row sizes of the array columns, chosen when the file is created.
/// Shorter results are padded with NaN (their true lengths are stored too).
struct ResultsLayout {
  /// Columns of /runs/trajectory_errors (inference trajectories per run).
  int num_inference = 100;
  /// Rows of /runs/trace per run: the max over runs of steps / eval_every + 2
  /// (step 0, every eval_every steps, the last step).
  int trace_points = 102;
  /// Points of each /runs/figure/* trajectory (x_0 ... x_500).
  int figure_points = 501;
  /// States per figure point: the most of any run (2 for the built-in
  /// systems); a run with fewer fills its first /runs/n_x of them.
  int figure_states = 2;
  /// Columns of /runs/checkpoint_* (the most TrainerOptions::checkpoints of
  /// any run); 0: those datasets are not created (files before them have none).
  int checkpoints = 0;
  /// Whether the file stores each run's best-validation weights (/weights,
  /// /runs/weights_offset, /runs/weights_length); for_runs sets it, files
  /// written before weights were stored have none.
  bool weights = false;

  /// The smallest layout that holds every run of `runs`: max num_inference,
  /// max steps / eval_every + 2, max num_inference_steps() + 1, max n_x.
  static ResultsLayout for_runs(const std::vector<RunConfig>& runs);

  /// Throws std::invalid_argument naming the field and value unless all > 0.
  void validate() const;
};

/// Where and how one session (one `phnn sweep` or `phnn train --out`
/// invocation) ran, as (key, value) string pairs: program_version,
/// git_commit, libtorch, blas, hdf5, mpi, compiler, hosts, ranks,
/// command_line, started (UTC); end_session adds finished.
using Provenance = std::vector<std::pair<std::string, std::string>>;

/// Per session of `sessions` (ResultsFile::read_sessions): true when at
/// least one run finished in it, i.e. one of `finished_utc`
/// (/runs/finished_utc, "" for runs not done) lies between the
/// session's `started` and its end (its `finished`, else the next session's
/// `started`, else open). Sessions without `started` count as having runs,
/// and so does every session when `finished_utc` is empty (a file that
/// records no run times).
std::vector<bool> sessions_with_runs(const std::vector<Provenance>& sessions,
                                     const std::vector<std::string>& finished_utc);

/// Largest stored strings; create() refuses longer canonical configs and
/// studies, write_run() truncates longer messages (ending them in "...").
constexpr std::size_t kCanonicalLength = 1024;
constexpr std::size_t kStudiesLength = 64;
constexpr std::size_t kMessageLength = 256;

/// The sweep's results file: one row per run (rows = the run list given to
/// create(), in order), every dataset allocated when the file is created so
/// that writing a row never changes HDF5 metadata and ranks write their rows
/// independently. Each row's status is written last, so a crash mid-row
/// leaves it pending; the Journal, not this file, is the source of truth for
/// recovery.
///
/// Collective calls (every rank of `comm`, same arguments): create, open,
/// store_system_data, flush, close (also the destructor). In a parallel file
/// an exception inside one of them is printed with the rank prefix and ends
/// the job with MPI_Abort; bad arguments and a wrong file are found before
/// the first collective HDF5 call and throw on every rank (docs/DECISIONS.md,
/// "No rank waits forever"). Independent calls: write_run and every read_*; their
/// errors throw std::runtime_error (h5::Error inside phnn) whose message
/// starts with "[rank r/n] " in a parallel file.
/// A file made with comm == MPI_COMM_NULL (or open_read_only) is serial and
/// needs no MPI_Init.
///
/// Usage:
///
///   ResultsFile out = ResultsFile::create(path, MPI_COMM_WORLD, runs, studies,
///       sweep.name, sweep.text, sweep.hash, program_version(), layout);
///   out.store_system_data("duffing", data);            // collective
///   for (int row : my_rows) out.write_run(row, train(runs[row]));
///   out.close();                                       // collective
class ResultsFile {
 public:
  /// Value of the file attribute "format" and of "format_version".
  static constexpr const char* kFormat = "phnn-results";
  static constexpr std::int64_t kFormatVersion = 1;
  /// The checksum rule of new files (file attribute "checksum_version";
  /// docs/RESULTS_FORMAT.md, "Checksums"): 2, every stored byte of a row,
  /// and a digest of /data, the sweep attributes and the configuration
  /// columns (2026-11-28). Files without the attribute keep rule 1: a row's
  /// checksum covers what read_run returns with its id, canonical and seed.
  static constexpr std::int64_t kChecksumVersion = 2;

  /// Collective over comm: creates (truncates) `path`, creates every dataset
  /// for `runs`, writes the config columns, the file attributes
  /// (format, format_version, sweep_name, sweep_text, sweep_hash,
  /// program_version, units, created) and status = pending for every row.
  /// `run_studies[i]` lists the studies of run i, e.g. "I,II,III". Throws
  /// std::invalid_argument (every rank alike) for mismatched sizes, duplicate
  /// run ids, a canonical() or studies string over its fixed length, a
  /// sweep_text over 60000 bytes, or an invalid layout; std::runtime_error if
  /// the directory of `path` is not writable. The journal of `path` is left
  /// alone (it may be what the new file is rebuilt from); a fresh start that
  /// must not replay old records calls remove_journals(path) first.
  ///
  /// kAtomic writes `<path>.creating` and renames it onto `path`; kInPlace
  /// writes `path` itself, for a caller whose `path` is already its own
  /// scratch name (phnn sweep), so messages never name a scratch of a scratch.
  enum class CreateMode { kAtomic, kInPlace };
  static ResultsFile create(const std::string& path, MPI_Comm comm,
                            const std::vector<RunConfig>& runs,
                            const std::vector<std::string>& run_studies,
                            const std::string& sweep_name,
                            const std::string& sweep_text,
                            const std::string& sweep_hash,
                            const std::string& program_version,
                            const ResultsLayout& layout,
                            CreateMode mode = CreateMode::kAtomic);

  /// Collective: opens an existing results file read-write, to resume. Throws
  /// std::runtime_error on every rank if `path` is missing, not HDF5, not a
  /// phnn results file, of another format version, or was written by a
  /// different sweep (sweep_hash != expected_sweep_hash), e.g.
  ///   results/paper.h5 was written by sweep 'demo' (hash 1a2b...), not by
  ///   this sweep file (hash 3c4d...); pass a new --out path or delete the file
  static ResultsFile open(const std::string& path, MPI_Comm comm,
                          const std::string& expected_sweep_hash);

  /// Serial, read-only (the reducer): the same checks as open() but the sweep
  /// hash.
  static ResultsFile open_read_only(const std::string& path);

  ResultsFile(ResultsFile&& other) noexcept;
  ResultsFile& operator=(ResultsFile&& other) noexcept;
  ResultsFile(const ResultsFile&) = delete;
  ResultsFile& operator=(const ResultsFile&) = delete;
  /// Closes the file: collective in parallel, like close().
  ~ResultsFile();

  const std::string& path() const;
  int num_runs() const;
  /// Read from the dataset shapes.
  const ResultsLayout& layout() const;

  /// File attributes.
  std::string sweep_name() const;
  std::string sweep_text() const;
  std::string sweep_hash() const;
  std::string program_version() const;
  /// UTC creation time, ISO 8601 ("2024-05-01T12:00:00Z").
  std::string created() const;

  /// Independent: writes every result column of row `row` (its run times
  /// too, where the file has them), the status last, then its checksum. Throws
  /// std::invalid_argument if the row is out of range or an array of
  /// `result` is longer than the layout allows (trajectory_errors >
  /// num_inference, trace > trace_points, a figure > figure_points points or
  /// of odd length); h5::Error if HDF5 fails. Messages over kMessageLength
  /// bytes are truncated.
  void write_run(int row, const RunResult& result);

  /// Independent reads.
  std::vector<RunStatus> read_statuses() const;
  /// Row `row` as written by write_run (bit-exact, except a truncated
  /// message); a pending row reads as a default RunResult with NaN scalars.
  /// Every integer is range-checked before it sizes or indexes anything (a
  /// length within the layout, n_x within figure_states, counts and steps
  /// within int, the weights within /weights): std::runtime_error naming
  /// the dataset, row and value.
  RunResult read_run(int row) const;

  /// Config columns, one entry per row.
  std::vector<std::string> read_run_ids() const;
  std::vector<std::string> read_canonical() const;
  std::vector<std::string> read_studies() const;  // "I,II"
  std::vector<std::int64_t> read_seeds() const;

  /// Every row's status, message and scalar result columns (config/
  /// result_columns.h), each read as a whole column; a column added after
  /// the file was written reads NaN. The arrays stay empty.
  std::vector<RunResult> read_result_columns() const;

  /// Any column of /runs by name ("mse", "wall_time_s", "figure/length",
  /// ...), flattened row-major over all rows.
  std::vector<double> read_double_column(const std::string& column) const;
  std::vector<std::int64_t> read_int_column(const std::string& column) const;
  std::vector<std::string> read_string_column(const std::string& column) const;

  /// Collective: stores one system's data set once under /data/<system_name>
  /// (every rank passes identical data; format_version 2 of data-set files,
  /// with the system file's text) and flushes the file. A system file's
  /// `sweep_entry` is the sweep file's `systems` value that named it, so that
  /// the sweep can be parsed again from this file alone
  /// (stored_system_files); "" for a built-in system.
  void store_system_data(const std::string& system_name, const PhSystemData& data,
                         const std::string& sweep_entry = "");
  /// True once store_system_data(system_name, ...) has completed.
  bool has_system_data(const std::string& system_name) const;
  /// Reads a stored data set (format_version 2, or 1: the built-in systems'
  /// layout before 2026-11-28, read as their system files' data).
  PhSystemData read_system_data(const std::string& system_name) const;
  /// The system files stored with their data sets, as a reader for
  /// parse_sweep_text: the text stored for the `systems` value `entry`;
  /// throws std::runtime_error naming the file when none is stored.
  SystemFileReader stored_system_files() const;

  /// sessions_with_runs(read_sessions(), /runs/finished_utc), every session
  /// counting in a file that records no run times (files written before
  /// provenance have no /runs/started_utc and finished_utc: write_run drops
  /// RunResult::started_utc and finished_utc there, read_run gives "").
  std::vector<bool> sessions_with_runs() const;

  /// Integrity (docs/RESULTS_FORMAT.md, "Checksums"): every row written by
  /// write_run carries a checksum of what it stores, by the file's rule
  /// (checksum_version()). The rows with a result (not pending) whose
  /// checksum is missing or wrong, or that cannot be read (a value out of
  /// range: read_run's message), and the pending rows that hold a checksum
  /// (a damaged status: only a row with a result has one); empty for a file
  /// written before checksums (has_checksums()).
  std::vector<int> damaged_rows() const;
  /// The same check for one row: true if it holds a result (not pending)
  /// whose checksum is missing or wrong, if it cannot be read, or if it is
  /// pending but holds a checksum; false in a file written before checksums. Every copy of a row into another file
  /// (merge, a grown sweep) asks this first (src/sweep/results_copy.h).
  bool row_damaged(int row) const;
  /// Why row `row` is damaged ("" if it is not): "checksum mismatch",
  /// read_run's message for a value out of range, or `/runs/status[r] = 0
  /// (pending) but /runs/checksum[r] is set ...`.
  std::string row_damage(int row) const;
  /// What makes the file unusable as a whole: an empty or repeated run id, a
  /// status outside 0..3, an unreadable column ("" entries none).
  std::vector<std::string> structure_problems() const;
  bool has_checksums() const;
  /// 0 (no checksums), 1 or 2: the rule of this file's checksums.
  std::int64_t checksum_version() const;
  /// The checksum of row `row` as stored now, by the file's rule.
  std::uint64_t row_checksum(int row) const;
  /// Independent: marks row `row` pending again (its result to be trained anew).
  void requeue_run(int row);
  /// "" if write_run(row, result) can rewrite every result column of row
  /// `row` from `result` (a journal record); else why not (an array longer
  /// than the layout, more weights than the row's room, a bad n_x). What
  /// `phnn verify` calls repairable is what `phnn sweep` repairs.
  std::string rewrite_problem(int row, const RunResult& result) const;

  /// A damaged object outside the result rows (file_damage).
  struct Damage {
    std::string object;  ///< "@sweep_text", "/runs/model", "/data/duffing/train/x"
    std::string what;    ///< what is wrong with it
  };
  /// Rule 2 only (empty otherwise): each object whose bytes differ from the
  /// digests recorded with the file: the sweep attributes (@sweep_name,
  /// @sweep_text, @sweep_hash) and configuration columns (/runs/id, ...,
  /// /runs/config/*) against the file digest, every object of each complete
  /// /data group against the group's digest; a damaged or missing digest
  /// or checksum_version attribute.
  std::vector<Damage> file_damage() const;
  /// Each configuration column whose values differ from what create()
  /// writes for `runs` (the runs of the file's sweep text), with the rows
  /// ("rows 3, 7 differ from the sweep file's runs"): names the rows of
  /// damage the file digest finds in a column.
  std::vector<Damage> configuration_differences(const std::vector<RunConfig>& runs,
                                                const std::vector<std::string>& run_studies) const;
  /// Rank 0 on a serial file: rewrites the sweep attributes and every
  /// configuration column from the sweep's own runs (the file's sweep text
  /// must hash to `sweep_hash`), as create() wrote them.
  void rewrite_configuration(const std::vector<RunConfig>& runs,
                             const std::vector<std::string>& run_studies,
                             const std::string& sweep_name, const std::string& sweep_text,
                             const std::string& sweep_hash);
  /// The repair of file_damage() outside /data (rule 2, serial): when the
  /// file digest finds damage, rewrite_configuration, then the digest is
  /// checked again. Returns the repaired objects (empty: nothing damaged);
  /// throws std::runtime_error naming the objects that rewriting does not
  /// restore to the recorded bytes.
  std::vector<std::string> repair_configuration(const std::vector<RunConfig>& runs,
                                                const std::vector<std::string>& run_studies,
                                                const std::string& sweep_name,
                                                const std::string& sweep_text,
                                                const std::string& sweep_hash);
  /// The same for /data/<system_name>: if its digest finds damage, the
  /// group is removed and `store` stores it again (store_system_data or
  /// store_file_system_data); the new bytes must be the recorded ones (or
  /// the old ones, when only the digest was damaged), else
  /// std::runtime_error. Returns the repaired objects.
  std::vector<std::string> repair_system_data(const std::string& system_name,
                                              const std::function<void()>& store);

  /// Collective (same `provenance` on every rank): records a session as the
  /// string attributes of a new group /provenance/session_<k> (k = 0, 1, ...
  /// in the order of the sessions) and returns k.
  int begin_session(const Provenance& provenance);
  /// Collective: sets attribute "finished" of the group of begin_session
  /// (no-op without one), in place: ending a session allocates no space.
  void end_session(const std::string& finished_utc);
  /// The same for session k of begin_session, e.g. from another handle.
  void end_session(int session, const std::string& finished_utc);
  /// Every session, in order; empty for files written before provenance.
  std::vector<Provenance> read_sessions() const;

  /// Collective: closes the file; later calls throw. Idempotent.
  void close();

 private:
  struct Impl;
  explicit ResultsFile(std::unique_ptr<Impl> impl);
  /// What write_run checks before it writes (the row, its n_x, the arrays
  /// against the layout, the weights against the row's room); returns where
  /// the weights go in /weights, -1 if none are stored. Throws with `where`.
  std::int64_t row_fit(int row, const RunResult& result, const std::string& where) const;
  /// read_run's figures and checkpoints of row `row`, into *result.
  void read_figures_and_checkpoints(int row, RunResult* result) const;
  /// Collective: /data/<system_name> written by `write(group)`, then marked complete.
  void store_data_group(const std::string& system_name,
                        const std::function<void(const std::string&)>& write);
  std::unique_ptr<Impl> impl_;
};

}  // namespace phnn
