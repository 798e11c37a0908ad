// src/sweep/version.cpp — build facts baked in by CMake (CMakeLists.txt;
// the commit from cmake/git_commit.cmake at build time).
#include "phnn/sweep/version.h"

#include "git_commit.h"

#ifndef PHNN_VERSION
#define PHNN_VERSION "unknown"
#endif
#ifndef PHNN_GIT_COMMIT
#define PHNN_GIT_COMMIT "unknown"
#endif

namespace phnn {

std::string program_version() { return std::string("phnn-sweep ") + PHNN_VERSION; }

std::string git_commit() { return PHNN_GIT_COMMIT; }

std::string compiler_version() {
#if defined(__clang__)
  return std::string("Clang ") + __clang_version__;
#elif defined(__GNUC__)
  return std::string("GNU ") + __VERSION__;
#else
  return "unknown";
#endif
}

}  // namespace phnn
