// include/phnn/sweep/version.h — what this program is: version, git commit,
// compiler (stored in every results file's provenance).
#pragma once

#include <string>

namespace phnn {

/// "phnn-sweep 0.1.0" (the CMake project version), stored in results files.
std::string program_version();

/// `git rev-parse HEAD` of the source tree when CMake configured the build,
/// with "-dirty" if it had uncommitted changes then; "unknown" outside git.
std::string git_commit();

/// "GNU 12.2.0" (compiler id and version of this build).
std::string compiler_version();

}  // namespace phnn
