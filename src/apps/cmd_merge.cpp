// src/apps/cmd_merge.cpp — `phnn merge OUT SHARD...`: the shards of one sweep
// (`phnn sweep --shard I/N`) into one results file (phnn/sweep/merge.h).
#include <iostream>

#include "apps/cli.h"
#include "apps/commands.h"
#include "apps/provenance.h"
#include "phnn/sweep/merge.h"
#include "phnn/sweep/version.h"

namespace phnn {
namespace apps {

int run_merge(int argc, char** argv, int first) {
  cli::Parser parser(
      "merge",
      "Merges the shard results files of one sweep (phnn sweep FILE --shard I/N, e.g.\n"
      "one per Slurm array task) into a new results file OUT: every run gets the result\n"
      "of the shard that trained it (a run finished in two shards must be bitwise equal\n"
      "in both), the data groups and every shard's provenance. Missing shards leave\n"
      "their runs pending; `phnn sweep FILE --out OUT` then trains just those.\n\n"
      "Example: phnn merge results/paper.h5 results/paper.shard-0-of-2.h5 results/paper.shard-1-of-2.h5");
  parser.positional("OUT", "new results file (must not exist)");
  parser.positional_rest("SHARD", "shard results files of one sweep file");
  parser.flag("mix-kernels", "merge shards computed with different kernel sets (their results "
                             "differ by round-off; refused without it)");
  if (!parser.parse(argc, argv, first)) return 0;
  if (!parser.flag_set("mix-kernels")) {
    std::string reference;
    for (const std::string& shard : parser.rest()) {
      const ResultsFile file = ResultsFile::open_read_only(shard);
      const auto sessions = file.read_sessions();
      const std::vector<bool> computed = file.sessions_with_runs();
      for (std::size_t k = 0; k < sessions.size() && reference.empty(); ++k) {
        if (computed[k]) reference = kernel_set_of(sessions[k]);
      }
      if (reference.empty()) continue;  // no finished run yet
      const std::string problem = kernel_mix_problem(sessions, computed, reference, shard);
      if (!problem.empty()) throw cli::UsageError{"phnn merge: " + problem};
    }
  }
  // The summary first: a merge that throws must not leave "phnn merge: " on
  // stdout before the error (it read as a doubled prefix in a job log).
  const std::string summary = merge_shards(parser.rest(), parser.get("OUT"), program_version());
  std::cout << "phnn merge: " << summary << "\n";
  return 0;
}

}  // namespace apps
}  // namespace phnn
