// src/systems/expression_code.h — GiNaC expressions handed to muParser
// (private to src/systems): a printer whose output does not depend on
// GiNaC's internal term order, and the compiled expressions that evaluate it.
//
// Why a printer of our own: GiNaC orders the operands of sums and products
// by hash values that include type-info addresses, so the same expression
// prints its terms in a different order from one process to the next
// (address-space randomization) and a floating-point evaluation of it rounds
// differently. muparser_source() sorts the operands of every sum and product
// by their own printed text, so the evaluation order, hence every bit of a
// system file's data, depends on the expression only.
#pragma once

#include <string>
#include <vector>

#include <ginac/ginac.h>
#include <muParser.h>

namespace phnn {
namespace internal {

/// muParser source of `e`: fully parenthesized, operands of sums and
/// products sorted by their text, numbers with 17 significant digits,
/// powers as products, phnn_sqrt, phnn_inv or phnn_pow(b, e), functions as phnn_<name>(...), all
/// correctly rounded (common/cr_math.h). Throws std::invalid_argument naming a function it cannot
/// evaluate.
std::string muparser_source(const GiNaC::ex& e);

/// Expressions (muparser_source text) compiled by muParser over variables
/// that live in a buffer owned by the caller (addresses must stay put);
/// eval() returns count() values. Throws mu::ParserError on what it cannot read.
class CompiledExpressions {
 public:
  CompiledExpressions(const std::vector<std::string>& sources, double* vars,
                      const std::vector<std::string>& names);
  const double* eval() const {
    int n = 0;
    return parser_.Eval(n);
  }
  int count() const { return count_; }

 private:
  mu::Parser parser_;
  int count_;
};

}  // namespace internal
}  // namespace phnn
