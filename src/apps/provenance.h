// src/apps/provenance.h — where and how this process runs, for results
// files (/provenance/session_<k>) and `phnn --version`.
#pragma once

#include <mpi.h>

#include <string>

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

/// `phnn --version`: one `key: value` line per build_provenance() entry.
std::string version_text();

}  // namespace apps
}  // namespace phnn
