// src/models/blas.h — the one BLAS routine the stacked networks call
// directly (libblas.so.3; OpenBLAS on Debian through its alternatives).
#pragma once

/// Column-major C = alpha op(A) op(B) + beta C (reference BLAS signature).
extern "C" void dgemm_(const char* transa, const char* transb, const int* m, const int* n,
                       const int* k, const double* alpha, const double* a, const int* lda,
                       const double* b, const int* ldb, const double* beta, double* c,
                       const int* ldc);
