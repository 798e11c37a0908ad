// tests/common/cr_math_test.cpp — phnn::cr against an independent reference:
// MPFR at 200 bits rounded once to the nearest double (a double rounding
// needs the 200-bit value within 2^-147 relative of a midpoint: never seen on
// random arguments). Every result must be that double, bit for bit.
#include <mpfr.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "phnn/common/cr_math.h"

namespace {

using Unary = int (*)(mpfr_ptr, mpfr_srcptr, mpfr_rnd_t);

double reference(Unary f, double x) {
  mpfr_t a, y;
  mpfr_inits2(200, a, y, static_cast<mpfr_ptr>(nullptr));
  mpfr_set_d(a, x, MPFR_RNDN);
  f(y, a, MPFR_RNDN);
  const double r = mpfr_get_d(y, MPFR_RNDN);
  mpfr_clears(a, y, static_cast<mpfr_ptr>(nullptr));
  return r;
}

std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// Equal bits, or both NaN.
bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || bits(a) == bits(b); }

// Compares `ours` with the reference on n uniform arguments in [lo, hi];
// returns the number of mismatches (and prints the first few).
int mismatches(const std::string& name, const std::function<double(double)>& ours, Unary f,
               double lo, double hi, int n, std::uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  int bad = 0;
  for (int i = 0; i < n; ++i) {
    const double x = u(rng);
    const double got = ours(x), want = reference(f, x);
    if (!same(got, want) && ++bad <= 3) {
      ADD_FAILURE() << name << "(" << x << ") = " << got << ", correctly rounded " << want;
    }
  }
  return bad;
}

void fast_paths_are_correctly_rounded(int n) {
  const long fallbacks_before = phnn::cr::fallback_count();
  struct Range {
    const char* name;
    double (*ours)(double);
    Unary reference;
    double lo, hi;
  };
  const Range ranges[] = {
      {"sin", phnn::cr::sin, mpfr_sin, -7.0, 7.0},         {"sin", phnn::cr::sin, mpfr_sin, -1e5, 1e5},
      {"sin", phnn::cr::sin, mpfr_sin, -1e-4, 1e-4},       {"cos", phnn::cr::cos, mpfr_cos, -7.0, 7.0},
      {"cos", phnn::cr::cos, mpfr_cos, -1e5, 1e5},         {"exp", phnn::cr::exp, mpfr_exp, -5.0, 5.0},
      {"exp", phnn::cr::exp, mpfr_exp, -700.0, 700.0},     {"log", phnn::cr::log, mpfr_log, 0.5, 2.0},
      {"log", phnn::cr::log, mpfr_log, 1e-300, 1e300},     {"tanh", phnn::cr::tanh, mpfr_tanh, -2.0, 2.0},
      {"tanh", phnn::cr::tanh, mpfr_tanh, -25.0, 25.0},    {"tanh", phnn::cr::tanh, mpfr_tanh, -1e-6, 1e-6},
      {"sinh", phnn::cr::sinh, mpfr_sinh, -1.0, 1.0},      {"sinh", phnn::cr::sinh, mpfr_sinh, -700.0, 700.0},
      {"cosh", phnn::cr::cosh, mpfr_cosh, -1.0, 1.0},      {"cosh", phnn::cr::cosh, mpfr_cosh, -700.0, 700.0},
  };
  std::uint32_t seed = 1;
  for (const Range& r : ranges) {
    EXPECT_EQ(mismatches(r.name, r.ours, r.reference, r.lo, r.hi, n, seed++), 0)
        << r.name << " on [" << r.lo << ", " << r.hi << "]";
  }
  // Each call that the rounding test cannot decide costs an MPFR call; with
  // the paths' error ~2^-65 and the test's bound 2^-63 that is ~2^-10 of them
  // (measured ~0.15 %); more than 1 % of the 16 n calls means a path is broken.
  const long fallbacks = phnn::cr::fallback_count() - fallbacks_before;
  EXPECT_LT(fallbacks, 16 * n / 100) << "the fast paths decide too few roundings";
}

// The build this CPU picks (with FMA here), then the baseline build that a
// CPU without FMA runs: both must be the correctly rounded result.
TEST(CrMathTest, FastPathsAreCorrectlyRoundedOnRandomArguments) {
  fast_paths_are_correctly_rounded(100000);
  phnn::cr::internal::use_baseline_fast_paths(true);
  fast_paths_are_correctly_rounded(30000);
  phnn::cr::internal::use_baseline_fast_paths(false);
}

TEST(CrMathTest, LogIsCorrectlyRoundedAcrossTheExponentRange) {
  // Random bit patterns of positive normal and subnormal doubles.
  std::mt19937_64 rng(11);
  int bad = 0;
  for (int i = 0; i < 50000; ++i) {
    const std::uint64_t b = rng() & 0x7fefffffffffffffULL;
    double x;
    std::memcpy(&x, &b, sizeof x);
    if (x == 0.0) continue;
    if (!same(phnn::cr::log(x), reference(mpfr_log, x)) && ++bad <= 3) {
      ADD_FAILURE() << "log(" << x << ")";
    }
  }
  EXPECT_EQ(bad, 0);
}

TEST(CrMathTest, EveryOtherFunctionIsCorrectlyRounded) {
  const int n = 5000;
  EXPECT_EQ(mismatches("tan", phnn::cr::tan, mpfr_tan, -1.5, 1.5, n, 21), 0);
  EXPECT_EQ(mismatches("asin", phnn::cr::asin, mpfr_asin, -1.0, 1.0, n, 22), 0);
  EXPECT_EQ(mismatches("acos", phnn::cr::acos, mpfr_acos, -1.0, 1.0, n, 23), 0);
  EXPECT_EQ(mismatches("atan", phnn::cr::atan, mpfr_atan, -20.0, 20.0, n, 24), 0);
  EXPECT_EQ(mismatches("sinh", phnn::cr::sinh, mpfr_sinh, -20.0, 20.0, n, 25), 0);
  EXPECT_EQ(mismatches("cosh", phnn::cr::cosh, mpfr_cosh, -20.0, 20.0, n, 26), 0);
  EXPECT_EQ(mismatches("tanh", phnn::cr::tanh, mpfr_tanh, -20.0, 20.0, n, 27), 0);
  EXPECT_EQ(mismatches("asinh", phnn::cr::asinh, mpfr_asinh, -20.0, 20.0, n, 28), 0);
  EXPECT_EQ(mismatches("acosh", phnn::cr::acosh, mpfr_acosh, 1.0, 20.0, n, 29), 0);
  EXPECT_EQ(mismatches("atanh", phnn::cr::atanh, mpfr_atanh, -1.0, 1.0, n, 30), 0);
  EXPECT_EQ(mismatches("cbrt", phnn::cr::cbrt, mpfr_cbrt, -20.0, 20.0, n, 31), 0);
  const auto pow_137 = [](double x) { return phnn::cr::pow(x, 1.37); };
  const Unary mpfr_pow_137 = [](mpfr_ptr y, mpfr_srcptr x, mpfr_rnd_t r) {
    mpfr_t e;
    mpfr_init2(e, 200);
    mpfr_set_d(e, 1.37, MPFR_RNDN);
    const int t = mpfr_pow(y, x, e, r);
    mpfr_clear(e);
    return t;
  };
  EXPECT_EQ(mismatches("pow(x, 1.37)", pow_137, mpfr_pow_137, 0.0, 50.0, n, 32), 0);
}

// Special values follow C99 Annex F, as the C library's do.
TEST(CrMathTest, SpecialValues) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(phnn::cr::sin(nan)));
  EXPECT_TRUE(std::isnan(phnn::cr::sin(inf)));
  EXPECT_TRUE(std::isnan(phnn::cr::cos(-inf)));
  EXPECT_EQ(bits(phnn::cr::sin(-0.0)), bits(-0.0));
  EXPECT_EQ(phnn::cr::cos(0.0), 1.0);
  EXPECT_EQ(phnn::cr::exp(0.0), 1.0);
  EXPECT_EQ(phnn::cr::exp(710.0), inf);
  EXPECT_EQ(phnn::cr::exp(-inf), 0.0);
  EXPECT_EQ(phnn::cr::exp(-746.0), 0.0);
  EXPECT_TRUE(same(phnn::cr::exp(-740.0), reference(mpfr_exp, -740.0)));  // subnormal
  EXPECT_GT(phnn::cr::exp(-740.0), 0.0);
  EXPECT_LT(phnn::cr::exp(-740.0), DBL_MIN);
  EXPECT_EQ(phnn::cr::log(0.0), -inf);
  EXPECT_EQ(phnn::cr::log(1.0), 0.0);
  EXPECT_EQ(phnn::cr::log(inf), inf);
  EXPECT_TRUE(std::isnan(phnn::cr::log(-1.0)));
  EXPECT_TRUE(same(phnn::cr::log(4.9e-324), reference(mpfr_log, 4.9e-324)));
  EXPECT_TRUE(same(phnn::cr::sin(1e300), reference(mpfr_sin, 1e300)));
  EXPECT_TRUE(same(phnn::cr::cos(0x1p20 + 0.5), reference(mpfr_cos, 0x1p20 + 0.5)));
  EXPECT_EQ(phnn::cr::pow(0.0, -1.0), inf);
  EXPECT_TRUE(std::isnan(phnn::cr::pow(-8.0, 1.0 / 3.0)));
  EXPECT_EQ(phnn::cr::pow(nan, 0.0), 1.0);
  EXPECT_EQ(phnn::cr::cbrt(-8.0), -2.0);
  EXPECT_TRUE(std::isnan(phnn::cr::tanh(nan)));
  EXPECT_EQ(phnn::cr::tanh(-inf), -1.0);
  EXPECT_EQ(phnn::cr::tanh(19.0), reference(mpfr_tanh, 19.0));
  EXPECT_EQ(bits(phnn::cr::tanh(-0.0)), bits(-0.0));
  EXPECT_EQ(phnn::cr::sinh(inf), inf);
  EXPECT_EQ(phnn::cr::sinh(-711.0), -inf);
  EXPECT_EQ(phnn::cr::cosh(-711.0), inf);
  EXPECT_TRUE(same(phnn::cr::sinh(710.0), reference(mpfr_sinh, 710.0)));
}

}  // namespace
