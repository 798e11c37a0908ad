// src/apps/provenance.cpp — library versions, hosts and command line of a
// session (see src/apps/provenance.h).
#include "apps/provenance.h"

#include <unistd.h>

#include <ctime>
#include <cstdlib>
#include <set>
#include <sstream>
#include <vector>

#include <torch/torch.h>
#include <torch/version.h>

#include "kernels/kernel_isa.h"
#include "phnn/store/file_probe.h"
#include "phnn/sweep/version.h"
#include "phnn/sweep/writer_lock.h"

// OpenBLAS names itself; another BLAS leaves this null (weak).
extern "C" char* openblas_get_config() __attribute__((weak));

namespace phnn {
namespace apps {
namespace {

// "BLAS_INFO=open" etc. from LibTorch's build configuration.
std::string torch_config_value(const std::string& key) {
  const std::string config = torch::show_config();
  const auto at = config.find(key + "=");
  if (at == std::string::npos) return "";
  const auto begin = at + key.size() + 1;
  const auto end = config.find_first_of(",\n", begin);
  return config.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

std::string blas_version() {
  std::string blas = openblas_get_config != nullptr ? std::string(openblas_get_config())
                                                    : std::string("libblas (not OpenBLAS)");
  const std::string torch_blas = torch_config_value("BLAS_INFO");
  if (!torch_blas.empty()) blas += "; LibTorch BLAS_INFO=" + torch_blas;
  return blas;
}

std::string mpi_version() {
  char text[MPI_MAX_LIBRARY_VERSION_STRING] = {};
  int length = 0;
  MPI_Get_library_version(text, &length);
  std::string version(text, static_cast<std::size_t>(length));
  while (!version.empty() && (version.back() == '\n' || version.back() == '\0')) version.pop_back();
  const auto comma = version.find(',');  // Open MPI appends a long package string
  return comma == std::string::npos ? version : version.substr(0, comma);
}

// argv as a shell would need it typed again (single quotes where needed).
std::string quoted_command_line(int argc, char** argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    std::string arg = argv[i];
    const bool plain = !arg.empty() && arg.find_first_not_of(
                                           "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                           "0123456789-_./=:,+@%") == std::string::npos;
    if (!plain) {
      std::string q = "'";
      for (char c : arg) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
      arg = q + "'";
    }
    line += (i ? " " : "") + arg;
  }
  return line;
}

// Distinct host names of every rank, sorted, comma-separated (collective).
std::string all_hosts(MPI_Comm comm) {
  if (comm == MPI_COMM_NULL) return host_name();
  constexpr int kLength = 256;
  char mine[kLength] = {};
  const std::string host = host_name();
  host.copy(mine, kLength - 1);
  int size = 1;
  MPI_Comm_size(comm, &size);
  std::vector<char> every(static_cast<std::size_t>(size) * kLength);
  MPI_Allgather(mine, kLength, MPI_CHAR, every.data(), kLength, MPI_CHAR, comm);
  std::set<std::string> hosts;
  for (int r = 0; r < size; ++r) hosts.insert(std::string(every.data() + r * kLength));
  std::string out;
  for (const std::string& h : hosts) out += (out.empty() ? "" : ",") + h;
  return out;
}

}  // namespace

std::string kernel_set_of(const Provenance& session) {
  for (const auto& [key, value] : session) {
    if (key == "kernels") return value.substr(0, value.find(';'));
  }
  return "no phnn kernels (BLAS and LibTorch chose by CPU)";
}

std::string kernel_mix_problem(const std::vector<Provenance>& sessions,
                               const std::vector<bool>& with_runs, const std::string& ours,
                               const std::string& file) {
  for (std::size_t k = 0; k < sessions.size(); ++k) {
    if (!with_runs[k]) continue;
    const std::string theirs = kernel_set_of(sessions[k]);
    if (theirs == ours) continue;
    return file + ": session " + std::to_string(k) + " computed its runs with " + theirs +
           ", this one uses " + ours +
           ": their results differ by round-off (docs/METHOD.md \"Deterministic kernels\"). "
           "Write to another file, or pass --mix-kernels to mix them anyway.";
  }
  return "";
}

Provenance build_provenance() {
  return {{"program_version", program_version()},
          {"git_commit", git_commit()},
          {"compiler", compiler_version()},
          {"libtorch", std::string("LibTorch ") + TORCH_VERSION},
          {"blas", blas_version()},
          {"kernels", internal::kernel_description()},
          {"hdf5", hdf5_library_version()},
          {"mpi", mpi_version()}};
}

Provenance session_provenance(MPI_Comm comm, int argc, char** argv) {
  Provenance p = build_provenance();
  int size = 1;
  if (comm != MPI_COMM_NULL) MPI_Comm_size(comm, &size);
  p.emplace_back("hosts", all_hosts(comm));
  p.emplace_back("ranks", std::to_string(size));
  p.emplace_back("command_line", quoted_command_line(argc, argv));
  p.emplace_back("started", utc_now());
  // Which Slurm job, array task and restart wrote this session (when set).
  auto env = [](const char* name) { const char* v = std::getenv(name); return v ? v : ""; };
  if (*env("SLURM_JOB_ID")) p.emplace_back("slurm_job", env("SLURM_JOB_ID"));
  if (*env("SLURM_ARRAY_JOB_ID")) {
    p.emplace_back("slurm_array",
                   std::string(env("SLURM_ARRAY_JOB_ID")) + "_" + env("SLURM_ARRAY_TASK_ID"));
  }
  if (*env("SLURM_RESTART_COUNT")) p.emplace_back("slurm_restarts", env("SLURM_RESTART_COUNT"));
  if (comm == MPI_COMM_NULL) return p;
  // Rank 0's entries everywhere (the start second, even which Slurm
  // variables are set, may differ between ranks).
  auto broadcast = [&](std::string* text) {
    unsigned long long n = text->size();
    MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm);
    text->resize(n);
    if (n > 0) MPI_Bcast(text->data(), static_cast<int>(n), MPI_CHAR, 0, comm);
  };
  unsigned long long entries = p.size();
  MPI_Bcast(&entries, 1, MPI_UNSIGNED_LONG_LONG, 0, comm);
  p.resize(entries);
  for (auto& [key, value] : p) {
    broadcast(&key);
    broadcast(&value);
  }
  return p;
}

std::string version_text() {
  std::ostringstream s;
  for (const auto& [key, value] : build_provenance()) s << key << ": " << value << "\n";
  return s.str();
}

}  // namespace apps
}  // namespace phnn
