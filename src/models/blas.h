// src/models/blas.h — the BLAS routines the stacked networks call directly
// (libblas.so.3; OpenBLAS on Debian through its alternatives): dgemm, and
// sgemm for float32 training on the reference networks.
#pragma once

/// Column-major C = alpha op(A) op(B) + beta C (reference BLAS signatures).
extern "C" void dgemm_(const char* transa, const char* transb, const int* m, const int* n,
                       const int* k, const double* alpha, const double* a, const int* lda,
                       const double* b, const int* ldb, const double* beta, double* c,
                       const int* ldc);
extern "C" void sgemm_(const char* transa, const char* transb, const int* m, const int* n,
                       const int* k, const float* alpha, const float* a, const int* lda,
                       const float* b, const int* ldb, const float* beta, float* c,
                       const int* ldc);
