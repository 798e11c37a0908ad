// src/systems/expression_code.cpp — GiNaC expressions printed in an order of
// their own and compiled by muParser (src/systems/expression_code.h).
#include "systems/expression_code.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>

namespace phnn {
namespace internal {
namespace {

using Fn1 = double (*)(double);

// GiNaC function name -> the one-argument function muParser calls for it.
const std::map<std::string, Fn1>& functions() {
  static const std::map<std::string, Fn1> table = {
      {"sin", [](double a) { return std::sin(a); }},
      {"cos", [](double a) { return std::cos(a); }},
      {"tan", [](double a) { return std::tan(a); }},
      {"asin", [](double a) { return std::asin(a); }},
      {"acos", [](double a) { return std::acos(a); }},
      {"atan", [](double a) { return std::atan(a); }},
      {"sinh", [](double a) { return std::sinh(a); }},
      {"cosh", [](double a) { return std::cosh(a); }},
      {"tanh", [](double a) { return std::tanh(a); }},
      {"asinh", [](double a) { return std::asinh(a); }},
      {"acosh", [](double a) { return std::acosh(a); }},
      {"atanh", [](double a) { return std::atanh(a); }},
      {"exp", [](double a) { return std::exp(a); }},
      {"log", [](double a) { return std::log(a); }},
      {"abs", [](double a) { return std::fabs(a); }},
      {"csgn", [](double a) { return a > 0 ? 1.0 : (a < 0 ? -1.0 : 0.0); }},
      {"step", [](double a) { return a > 0 ? 1.0 : (a < 0 ? 0.0 : 0.5); }},
  };
  return table;
}

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
  if (is_a<GiNaC::power>(e)) {
    // muParser's ^ (std::pow; integer exponents up to 4 as products).
    return "(" + muparser_source(e.op(0)) + "^" + muparser_source(e.op(1)) + ")";
  }
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
  std::string joined;
  for (const std::string& s : sources) joined += (joined.empty() ? "" : ",") + s;
  parser_.SetExpr(joined);
  int n = 0;
  parser_.Eval(n);  // compiles; throws mu::ParserError on what it cannot read
}

}  // namespace internal
}  // namespace phnn
