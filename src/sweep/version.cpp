// src/sweep/version.cpp
#include "phnn/sweep/version.h"

#ifndef PHNN_VERSION
#define PHNN_VERSION "unknown"
#endif

namespace phnn {

std::string program_version() { return std::string("phnn-sweep ") + PHNN_VERSION; }

}  // namespace phnn
