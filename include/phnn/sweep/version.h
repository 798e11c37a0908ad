// include/phnn/sweep/version.h — what this program is: version, git commit,
// compiler (stored in every results file's provenance).
#pragma once

#include <string>

namespace phnn {

/// "phnn-sweep 0.1.0" (the CMake project version), stored in results files.
std::string program_version();

/// `git rev-parse HEAD` of the source tree when the binary was built (every
/// build refreshes it: cmake/git_commit.cmake), with "-dirty" if tracked
/// files differed from it then; "unknown" outside git.
std::string git_commit();

/// "GNU 12.2.0" (compiler id and version of this build).
std::string compiler_version();

}  // namespace phnn
