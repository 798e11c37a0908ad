// include/phnn/sweep/version.h
#pragma once

#include <string>

namespace phnn {

/// "phnn-sweep 0.1.0" (the CMake project version), stored in results files.
std::string program_version();

}  // namespace phnn
