// src/systems/expression_bounds.h — the size limits of a system file's
// expressions (private to src/systems), checked on the text before GiNaC
// sees it: GiNaC folds numbers and powers while it parses and expands
// polynomials without a way to stop, so an expression such as (q^2)^1000000
// must be refused before it reaches GiNaC (sweeps/FORMAT.md, "Limits and
// errors").
#pragma once

#include <map>
#include <set>
#include <string>

namespace phnn {
namespace internal {

/// A power's exponent, when it is a number (or made of numbers and
/// parameters), lies in [-kMaxExponent, kMaxExponent].
constexpr double kMaxExponent = 100;

/// Upper bound on the terms of any part of an expression once expanded (the
/// Gonzalez defect of H expands H(a + d/2)): counted on the expression as
/// written, a number or parameter 1, a variable 2 (a + d/2), a sum the sum
/// of its operands', a product or quotient the product, a power b^n with a
/// number n the monomials of degree floor(|n|) in b's terms,
/// C(t + n - 1, n), anything else 1 (its arguments counted on their own).
constexpr double kMaxExpandedTerms = 20000;

/// What the checks may know about the symbols of an expression.
struct ExpressionSymbols {
  std::set<std::string> variables;          ///< states (H) or ports (z)
  std::map<std::string, double> constants;  ///< [parameters], by name
};

/// "" if `text` is within the limits above, with every part made only of
/// numbers and parameters a finite double; else what is wrong, e.g.
/// `the exponent 1000000 in "(q^2)^1000000" is out of range; ...`. Text that
/// does not parse as + - * / ^, parentheses, numbers, names and f(args)
/// is refused too (`is not an expression ...`). Never throws.
std::string expression_bound_problem(const std::string& text, const ExpressionSymbols& symbols);

}  // namespace internal
}  // namespace phnn
