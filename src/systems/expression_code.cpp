// src/systems/expression_code.cpp — GiNaC expressions printed in an order of
// their own and compiled by muParser (src/systems/expression_code.h).
#include "systems/expression_code.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>

#include "phnn/common/cr_math.h"

namespace phnn {
namespace internal {
namespace {

using Fn1 = double (*)(double);

// GiNaC function name -> the one-argument function muParser calls for it:
// correctly rounded (common/cr_math.h), so a system file's data are the
// same bits whichever variant of the C library's functions a CPU gets.
const std::map<std::string, Fn1>& functions() {
  static const std::map<std::string, Fn1> table = {
      {"sin", cr::sin},
      {"cos", cr::cos},
      {"tan", cr::tan},
      {"asin", cr::asin},
      {"acos", cr::acos},
      {"atan", cr::atan},
      {"sinh", cr::sinh},
      {"cosh", cr::cosh},
      {"tanh", cr::tanh},
      {"asinh", cr::asinh},
      {"acosh", cr::acosh},
      {"atanh", cr::atanh},
      {"exp", cr::exp},
      {"log", cr::log},
      {"abs", [](double a) { return std::fabs(a); }},
      {"csgn", [](double a) { return a > 0 ? 1.0 : (a < 0 ? -1.0 : 0.0); }},
      {"step", [](double a) { return a > 0 ? 1.0 : (a < 0 ? 0.0 : 0.5); }},
  };
  return table;
}

// Powers that need no std::pow (whose glibc version differs with the CPU's
// FMA support, and which is ~10x a product): b^2, b^3, b^4 as products,
// b^(1/2) by the correctly rounded sqrt, negative exponents as 1 / b^|n|
// (GiNaC writes every quotient as a power -1).
const std::map<std::string, Fn1>& power_functions() {
  static const std::map<std::string, Fn1> table = {
      {"sq", [](double a) { return a * a; }},
      {"cube", [](double a) { return (a * a) * a; }},
      {"pow4", [](double a) { const double s = a * a; return s * s; }},
      {"sqrt", [](double a) { return std::sqrt(a); }},
      {"inv", [](double a) { return 1.0 / a; }},
  };
  return table;
}

std::string power_source(const GiNaC::ex& base, const GiNaC::ex& exponent);

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return std::string("(") + buf + ")";
}

// The operands of a sum or product, printed and sorted, joined by `op`.
std::string sorted_operands(const GiNaC::ex& e, const char* op) {
  std::vector<std::string> parts;
  for (std::size_t i = 0; i < e.nops(); ++i) parts.push_back(muparser_source(e.op(i)));
  std::sort(parts.begin(), parts.end());
  std::string out = "(";
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? op : "") + parts[i];
  return out + ")";
}

std::string power_source(const GiNaC::ex& base, const GiNaC::ex& exponent) {
  const std::string b = muparser_source(base);
  if (GiNaC::is_a<GiNaC::numeric>(exponent)) {
    const GiNaC::numeric n = GiNaC::ex_to<GiNaC::numeric>(exponent);
    const GiNaC::numeric a = GiNaC::abs(n);
    std::string positive;
    if (a == 2) positive = "phnn_sq(" + b + ")";
    if (a == 3) positive = "phnn_cube(" + b + ")";
    if (a == 4) positive = "phnn_pow4(" + b + ")";
    if (a == GiNaC::numeric(1, 2)) positive = "phnn_sqrt(" + b + ")";
    if (a == 1) positive = b;
    if (!positive.empty()) return n.is_negative() ? "phnn_inv(" + positive + ")" : positive;
  }
  return "phnn_pow(" + b + "," + muparser_source(exponent) + ")";
}

}  // namespace

std::string muparser_source(const GiNaC::ex& e) {
  using GiNaC::is_a;
  if (is_a<GiNaC::numeric>(e)) {
    const GiNaC::numeric& n = GiNaC::ex_to<GiNaC::numeric>(e);
    if (!n.is_real()) throw std::invalid_argument("a complex number");
    return number(n.to_double());
  }
  if (is_a<GiNaC::symbol>(e)) return GiNaC::ex_to<GiNaC::symbol>(e).get_name();
  if (is_a<GiNaC::constant>(e)) return number(GiNaC::ex_to<GiNaC::numeric>(e.evalf()).to_double());
  if (is_a<GiNaC::add>(e)) return sorted_operands(e, "+");
  if (is_a<GiNaC::mul>(e)) return sorted_operands(e, "*");
  if (is_a<GiNaC::power>(e)) return power_source(e.op(0), e.op(1));
  if (is_a<GiNaC::function>(e)) {
    const std::string name = GiNaC::ex_to<GiNaC::function>(e).get_name();
    if (functions().count(name) == 0 || e.nops() != 1) {
      throw std::invalid_argument("the function " + name);
    }
    return "phnn_" + name + "(" + muparser_source(e.op(0)) + ")";
  }
  std::ostringstream os;
  os << e;
  throw std::invalid_argument("the term " + os.str());
}

CompiledExpressions::CompiledExpressions(const std::vector<std::string>& sources, double* vars,
                                         const std::vector<std::string>& names)
    : count_(static_cast<int>(sources.size())) {
  if (count_ == 0) return;
  for (std::size_t i = 0; i < names.size(); ++i) parser_.DefineVar(names[i], vars + i);
  for (const auto& [name, f] : functions()) parser_.DefineFun("phnn_" + name, f);
  for (const auto& [name, f] : power_functions()) parser_.DefineFun("phnn_" + name, f);
  parser_.DefineFun("phnn_pow", static_cast<double (*)(double, double)>(cr::pow));
  std::string joined;
  for (const std::string& s : sources) joined += (joined.empty() ? "" : ",") + s;
  parser_.SetExpr(joined);
  int n = 0;
  parser_.Eval(n);  // compiles; throws mu::ParserError on what it cannot read
}

}  // namespace internal
}  // namespace phnn
