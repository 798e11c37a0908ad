// src/systems/expression_bounds.cpp — see expression_bounds.h: a recursive-
// descent reader of the expression grammar GiNaC's parser takes, which
// counts terms and folds numbers in doubles instead of building anything.
#include "systems/expression_bounds.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <optional>
#include <vector>

namespace phnn {
namespace internal {
namespace {

constexpr int kMaxDepth = 200;  // nesting of parentheses, powers and calls

// What the reader knows of a part of the expression.
struct Part {
  double terms = 1;             // upper bound on its terms once expanded
  std::optional<double> value;  // set if made of numbers and parameters only
};

struct Refused {
  std::string message;
};

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// C(t + n - 1, n): the monomials of degree n in t terms (capped, no overflow).
double monomials(double t, double n) {
  double r = 1;
  for (double k = 1; k <= n && r < 1e300; ++k) r = r * (t - 1 + k) / k;
  return r;
}

std::optional<double> apply(const std::string& f, double x) {
  static const std::map<std::string, std::function<double(double)>> table = {
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
      {"sqrt", [](double a) { return std::sqrt(a); }},
      {"abs", [](double a) { return std::abs(a); }},
  };
  const auto it = table.find(f);
  if (it == table.end()) return std::nullopt;
  const double y = it->second(x);
  if (!std::isfinite(y)) return std::nullopt;  // GiNaC keeps it symbolic or says why
  return y;
}

class Reader {
 public:
  Reader(const std::string& text, const ExpressionSymbols& symbols)
      : text_(text), symbols_(symbols) {}

  void read() {
    sum(0);
    skip_space();
    if (pos_ < text_.size()) fail_syntax("an unexpected \"" + text_.substr(pos_, 1) + "\"");
  }

 private:
  // sum := product (('+' | '-') product)*
  Part sum(int depth) {
    Part a = product(depth);
    while (peek('+') || peek('-')) {
      const char op = text_[pos_++];
      const Part b = product(depth);
      a.terms = limit(a.terms + b.terms);
      a.value = a.value && b.value
                    ? std::optional<double>(op == '+' ? *a.value + *b.value : *a.value - *b.value)
                    : std::nullopt;
    }
    return a;
  }

  // product := unary (('*' | '/') unary)*
  Part product(int depth) {
    Part a = unary(depth);
    while (peek('*') || peek('/')) {
      const char op = text_[pos_++];
      const Part b = unary(depth);
      a.terms = limit(a.terms * b.terms);
      a.value = a.value && b.value
                    ? std::optional<double>(op == '*' ? *a.value * *b.value : *a.value / *b.value)
                    : std::nullopt;
      if (a.value && !std::isfinite(*a.value)) a.value.reset();  // x/0: GiNaC says why
    }
    return a;
  }

  // unary := ('-' | '+') unary | power
  Part unary(int depth) {
    if (depth > kMaxDepth) {
      throw Refused{"nests parentheses, powers or calls more than " + std::to_string(kMaxDepth) +
                    " deep; write it flatter"};
    }
    if (peek('-') || peek('+')) {
      const char op = text_[pos_++];
      Part a = unary(depth + 1);
      if (a.value && op == '-') a.value = -*a.value;
      return a;
    }
    return power(depth);
  }

  // power := primary ('^' unary)?
  Part power(int depth) {
    const std::size_t start = pos_;
    Part base = primary(depth + 1);
    if (!peek('^')) return base;
    ++pos_;
    const Part exponent = unary(depth + 1);
    const std::string written = trimmed(start, pos_);
    Part out;
    if (exponent.value) {
      const double n = *exponent.value;
      if (!(std::abs(n) <= kMaxExponent)) {
        throw Refused{"the exponent " + number_text(n) + " in \"" + written +
                      "\" is out of range; a power whose exponent is a number (or made of "
                      "numbers and parameters) needs |exponent| <= " +
                      number_text(kMaxExponent)};
      }
      out.terms = limit(monomials(base.terms, std::floor(std::abs(n))), written);
      if (base.value) {
        out.value = std::pow(*base.value, n);
        if (std::isinf(*out.value)) {
          throw Refused{"\"" + written + "\" = " + number_text(*base.value) + "^" + number_text(n) +
                        " overflows a double (> 1.8e308); keep every number "
                        "in range (the data are computed in doubles)"};
        }
        if (std::isnan(*out.value)) out.value.reset();
      }
    }
    return out;
  }

  // primary := number | name | name '(' sum (',' sum)* ')' | '(' sum ')'
  Part primary(int depth) {
    skip_space();
    if (pos_ >= text_.size()) fail_syntax("an unexpected end");
    const char c = text_[pos_];
    if (c == '(') {
      ++pos_;
      Part inner = sum(depth);
      expect(')');
      return inner;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number();
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') return name(depth);
    fail_syntax("an unexpected \"" + std::string(1, c) + "\"");
    return {};
  }

  Part number() {
    const char* begin = text_.c_str() + pos_;
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    if (end == begin) fail_syntax("a malformed number");
    pos_ += static_cast<std::size_t>(end - begin);
    if (!std::isfinite(v)) {
      const std::string written(begin, static_cast<std::size_t>(end - begin));
      throw Refused{"the number " + written + " overflows a double (> 1.8e308)"};
    }
    return Part{1, v};
  }

  Part name(int depth) {
    const std::size_t start = pos_;
    while (pos_ < text_.size() &&
           (std::isalnum(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '_')) {
      ++pos_;
    }
    const std::string id = text_.substr(start, pos_ - start);
    if (!peek('(')) {
      if (symbols_.variables.count(id)) return Part{2, std::nullopt};
      const auto it = symbols_.constants.find(id);
      return it == symbols_.constants.end() ? Part{1, std::nullopt} : Part{1, it->second};
    }
    ++pos_;
    std::vector<Part> args{sum(depth)};
    while (peek(',')) {
      ++pos_;
      args.push_back(sum(depth));
    }
    expect(')');
    Part out;  // one term whatever its arguments (each counted on its own)
    if (args.size() == 1 && args[0].value) out.value = apply(id, *args[0].value);
    return out;
  }

  double limit(double terms, const std::string& where = "") const {
    if (terms <= kMaxExpandedTerms) return terms;
    throw Refused{"expands to more than " + number_text(kMaxExpandedTerms) + " terms (bound " +
                  number_text(terms) + (where.empty() ? "" : " for \"" + where + "\"") +
                  "); split the energy into smaller parts or lower its degree"};
  }

  bool peek(char c) {
    skip_space();
    return pos_ < text_.size() && text_[pos_] == c;
  }
  void expect(char c) {
    if (!peek(c)) fail_syntax("a missing \"" + std::string(1, c) + "\"");
    ++pos_;
  }
  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  std::string trimmed(std::size_t from, std::size_t to) const {
    std::string s = text_.substr(from, to - from);
    const std::size_t first = s.find_first_not_of(" \t");
    return first == std::string::npos ? s : s.substr(first);
  }
  [[noreturn]] void fail_syntax(const std::string& what) const {
    throw Refused{"is not an expression (" + what + " at column " + std::to_string(pos_ + 1) + ")"};
  }

  const std::string& text_;
  const ExpressionSymbols& symbols_;
  std::size_t pos_ = 0;
};

}  // namespace

std::string expression_bound_problem(const std::string& text, const ExpressionSymbols& symbols) {
  try {
    Reader(text, symbols).read();
  } catch (const Refused& r) {
    return r.message;
  }
  return "";
}

}  // namespace internal
}  // namespace phnn
