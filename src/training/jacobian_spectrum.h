// src/training/jacobian_spectrum.h — singular values and real parts of the
// eigenvalues of small square matrices, differentiable (private to
// src/training; the n-dimensional regularizers of regularizers.cpp).
//
// Why not torch::linalg_svdvals / linalg_eigvals: they run LAPACK in
// OpenBLAS, whose inner kernels (dnrm2, drot, dgemv, ...) are chosen at run
// time by CPU, so their last bits may change from one machine to the next
// (not observed on the dispatch test's cells; the pin is by construction,
// docs/METHOD.md "n-dimensional systems and models"). Eigen's JacobiSVD and
// EigenSolver are compiled into this binary with fixed flags: the same
// operations on every x86-64 CPU. Forward: per matrix; backward by the
// first-order formulas (simple singular values and eigenvalues):
//   d sigma_i = u_i^T dJ v_i             (J = U diag(sigma) V^T)
//   d lambda_k = (V^-1 dJ V)_kk          (J = V diag(lambda) V^-1)
// with each sum written as a loop in one order (no BLAS).
#pragma once

#include <torch/torch.h>

namespace phnn {
namespace internal {

/// Singular values of every matrix of J [.., n, n], descending: [.., n].
torch::Tensor singular_values(const torch::Tensor& jacobian);
/// Re(lambda_k) of every matrix of J [.., n, n] (Eigen's order): [.., n].
torch::Tensor eigenvalue_real_parts(const torch::Tensor& jacobian);

}  // namespace internal
}  // namespace phnn
