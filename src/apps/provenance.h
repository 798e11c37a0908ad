// src/apps/provenance.h — where and how this process runs, for results
// files (/provenance/session_<k>) and `phnn --version`.
#pragma once

#include <mpi.h>

#include <string>
#include <vector>

#include "phnn/common/utc_time.h"
#include "phnn/store/results_file.h"

namespace phnn {
namespace apps {

/// program_version, git_commit, compiler, libtorch, blas, hdf5, mpi.
Provenance build_provenance();

/// build_provenance() plus hosts (sorted, distinct, comma-separated), ranks,
/// command_line and started (now). Collective over `comm` (gathers the host
/// names; MPI_COMM_NULL: this host, 1 rank); every rank gets rank 0's values.
Provenance session_provenance(MPI_Comm comm, int argc, char** argv);

/// The kernel set a session's runs were computed with: "phnn kernels N"
/// from its `kernels` entry, or, for files written before that entry
/// existed, "no phnn kernels (BLAS and LibTorch chose by CPU)".
std::string kernel_set_of(const Provenance& session);

/// "" when every session in `sessions` that finished a run (`with_runs`:
/// ResultsFile::sessions_with_runs) used `ours` (kernel_set_of), else a message naming
/// the first that did not, its set and the way out; for resume and merge,
/// which refuse to mix kernel sets (their results differ by round-off)
/// unless told to (--mix-kernels). A session that finished no run (stopped
/// at once, or refused) mixes nothing.
std::string kernel_mix_problem(const std::vector<Provenance>& sessions,
                               const std::vector<bool>& with_runs, const std::string& ours,
                               const std::string& file);

/// `phnn --version`: one `key: value` line per build_provenance() entry.
std::string version_text();

}  // namespace apps
}  // namespace phnn
