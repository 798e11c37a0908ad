// include/phnn/common/check.h — invariant and option checks (PHNN_REQUIRE,
// PHNN_CHECK, PHNN_OPTION_*): the exceptions a bug and bad input throw.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace phnn {

/// Thrown when an internal invariant does not hold (a bug, not bad input).
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

}  // namespace phnn

/// PHNN_CHECK(cond, "message " << value): throws phnn::InternalError with the
/// streamed message, the failed expression and file:line (MFEM_VERIFY).
#define PHNN_CHECK(cond, msg)                                              \
  do {                                                                     \
    if (!(cond)) {                                                         \
      std::ostringstream phnn_check_stream_;                               \
      phnn_check_stream_ << msg << " [check failed: " #cond " at "         \
                         << __FILE__ << ":" << __LINE__ << "]";            \
      throw ::phnn::InternalError(phnn_check_stream_.str());               \
    }                                                                      \
  } while (false)

/// PHNN_REQUIRE(cond, "message"): throws std::invalid_argument with the
/// message alone, for user-facing validation (Options::validate()).
#define PHNN_REQUIRE(cond, msg)                                            \
  do {                                                                     \
    if (!(cond)) {                                                         \
      std::ostringstream phnn_require_stream_;                             \
      phnn_require_stream_ << msg;                                         \
      throw std::invalid_argument(phnn_require_stream_.str());             \
    }                                                                      \
  } while (false)
