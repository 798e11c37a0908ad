// src/models/head_sizes.h — compile-time sizes for the n-state heads' row
// loops (general_heads.cpp, general_field_heads.cpp): a row kernel is a
// template over N (N > 0: the size is N; N = 0: the size given at run time),
// and with_size(n, f) calls f(std::integral_constant<int, N>) with N = n for
// n = 1..kMaxHeadSize and N = 0 above. The loops are the same either way (the
// compiler unrolls the fixed ones), so every size gives the same bits as the
// run-time loop. Private to src/models.
#pragma once

#include <type_traits>

namespace phnn {
namespace internal {

constexpr int kMaxHeadSize = 8;

template <class F>
decltype(auto) with_size(int n, F&& f) {
  switch (n) {
    case 1:
      return f(std::integral_constant<int, 1>{});
    case 2:
      return f(std::integral_constant<int, 2>{});
    case 3:
      return f(std::integral_constant<int, 3>{});
    case 4:
      return f(std::integral_constant<int, 4>{});
    case 5:
      return f(std::integral_constant<int, 5>{});
    case 6:
      return f(std::integral_constant<int, 6>{});
    case 7:
      return f(std::integral_constant<int, 7>{});
    case 8:
      return f(std::integral_constant<int, 8>{});
    default:
      return f(std::integral_constant<int, 0>{});
  }
}

/// The loop bound of a kernel instantiated for N: N, or the run-time n when N = 0.
template <int N>
constexpr int size_of(int n) {
  return N > 0 ? N : n;
}

/// The same for a count that may be 0 (inputs, ports): N = n for n = 0..2,
/// N = -1 above; count_of<N>(n) is the loop bound.
template <class F>
decltype(auto) with_count(int n, F&& f) {
  switch (n) {
    case 0:
      return f(std::integral_constant<int, 0>{});
    case 1:
      return f(std::integral_constant<int, 1>{});
    case 2:
      return f(std::integral_constant<int, 2>{});
    default:
      return f(std::integral_constant<int, -1>{});
  }
}

template <int N>
constexpr int count_of(int n) {
  return N >= 0 ? N : n;
}

}  // namespace internal
}  // namespace phnn
