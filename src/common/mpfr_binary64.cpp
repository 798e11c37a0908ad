// src/common/mpfr_binary64.cpp — MPFR as binary64 arithmetic
// (src/common/mpfr_binary64.h): 53-bit operands and results in a per-thread
// scratch, MPFR's exponent range narrowed to binary64's around each call.
#include "common/mpfr_binary64.h"

#include <mutex>

namespace phnn {
namespace cr {
namespace internal {
namespace {

struct Scratch {
  mpfr_t a, b, y;
  Scratch() { mpfr_inits2(53, a, b, y, static_cast<mpfr_ptr>(nullptr)); }
  ~Scratch() { mpfr_clears(a, b, y, static_cast<mpfr_ptr>(nullptr)); }
};

Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

// MPFR's exponent range narrowed to binary64's for one call (exponents of
// MPFR's [1/2, 1) mantissas: 2^-1074 has -1073, DBL_MAX has 1024), so that
// mpfr_subnormalize rounds tiny results as IEEE arithmetic does.
class Binary64Range {
 public:
  Binary64Range() : emin_(mpfr_get_emin()), emax_(mpfr_get_emax()) {
    mpfr_set_emin(-1073);
    mpfr_set_emax(1024);
  }
  ~Binary64Range() {
    mpfr_set_emin(emin_);
    mpfr_set_emax(emax_);
  }
  Binary64Range(const Binary64Range&) = delete;
  Binary64Range& operator=(const Binary64Range&) = delete;

 private:
  mpfr_exp_t emin_, emax_;
};

// MPFR keeps its exponent range per thread when built with thread-local
// storage (Debian's is); otherwise the calls take turns.
std::unique_lock<std::mutex> exclusive_unless_thread_local() {
  static const bool thread_local_state = mpfr_buildopt_tls_p() != 0;
  static std::mutex mutex;
  return thread_local_state ? std::unique_lock<std::mutex>() : std::unique_lock<std::mutex>(mutex);
}

double rounded(Scratch& s, int ternary) {
  mpfr_subnormalize(s.y, ternary, MPFR_RNDN);
  return mpfr_get_d(s.y, MPFR_RNDN);
}

}  // namespace

double by_mpfr(MpfrUnary f, double x) {
  Scratch& s = scratch();
  const auto lock = exclusive_unless_thread_local();
  const Binary64Range range;
  mpfr_set_d(s.a, x, MPFR_RNDN);  // exact: 53 bits, binary64's exponents
  return rounded(s, f(s.y, s.a, MPFR_RNDN));
}

double by_mpfr(MpfrBinary f, double x, double y) {
  Scratch& s = scratch();
  const auto lock = exclusive_unless_thread_local();
  const Binary64Range range;
  mpfr_set_d(s.a, x, MPFR_RNDN);
  mpfr_set_d(s.b, y, MPFR_RNDN);
  return rounded(s, f(s.y, s.a, s.b, MPFR_RNDN));
}

}  // namespace internal
}  // namespace cr
}  // namespace phnn
