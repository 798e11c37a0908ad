// tests/integrators/small_lu_test.cpp — include/phnn/common/small_lu.h
// against Eigen's full-pivoting LU (an independent factorization), a factor
// reused for several right-hand sides, the first of tied pivots, and a
// singular matrix (inf/NaN, no exception).
#include "phnn/common/small_lu.h"

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

namespace phnn {
namespace {

using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Random well-conditioned systems, n = 1..12, three right-hand sides per
// factor: x agrees with FullPivLU's to 1e-12 relative (cond(A) < 1e2 for a
// diagonally shifted random matrix, so both errors are ~1e-14).
TEST(SmallLuTest, SolvesLikeAnIndependentFactorization) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int n = 1; n <= 12; ++n) {
    Mat a(n, n);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) a(i, j) = uniform(rng) + (i == j ? 2.0 * n : 0.0);
    }
    Mat lu = a;
    std::vector<int> perm(static_cast<std::size_t>(n));
    lu_factor(lu.data(), perm.data(), n);
    const Eigen::FullPivLU<Mat> reference(a);
    for (int rhs = 0; rhs < 3; ++rhs) {
      Eigen::VectorXd b(n);
      for (int i = 0; i < n; ++i) b(i) = uniform(rng);
      Eigen::VectorXd x = b;
      lu_solve(lu.data(), perm.data(), x.data(), n);
      const Eigen::VectorXd expected = reference.solve(b);
      EXPECT_LE((x - expected).norm(), 1e-12 * expected.norm()) << "n = " << n;
    }
  }
}

// Rows 1 and 2 tie for the largest |a_i0| (4 and -4): step 0 takes the
// first, row 1. After the swap the rows are (4,0,0), (1,2,0), (-4,1,1),
// the multipliers 1/4 and -1, and column 1 below the diagonal holds 2 and
// 1: no swap at step 1.
TEST(SmallLuTest, PivotsOnTheFirstLargestEntry) {
  double a[9] = {1.0, 2.0, 0.0,  //
                 4.0, 0.0, 0.0,  //
                 -4.0, 1.0, 1.0};
  int perm[3];
  lu_factor(a, perm, 3);
  EXPECT_EQ(perm[0], 1);
  EXPECT_EQ(perm[1], 1);
  EXPECT_EQ(a[3], 0.25);
  EXPECT_EQ(a[6], -1.0);
  double b[3] = {3.0, 4.0, -2.0};  // A (1, 1, 1)
  lu_solve(a, perm, b, 3);
  for (double v : b) EXPECT_DOUBLE_EQ(v, 1.0);
}

TEST(SmallLuTest, ASingularMatrixGivesNonFiniteValuesWithoutThrowing) {
  double a[4] = {1.0, 2.0, 2.0, 4.0};
  int perm[2];
  lu_factor(a, perm, 2);
  double b[2] = {1.0, 1.0};
  lu_solve(a, perm, b, 2);
  EXPECT_FALSE(std::isfinite(b[0]) && std::isfinite(b[1]));
}

}  // namespace
}  // namespace phnn
