// src/store/journal_record.cpp — one journal line: every RunResult field
// written exactly (hex floats, NaN payloads, percent-escaped strings; the
// scalar ones from config/result_columns.h) and a checksum, and its parser.
// The files themselves: journal.cpp.
#include <locale.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "phnn/config/result_columns.h"
#include "phnn/config/run_config.h"  // fnv1a64, hex64
#include "phnn/store/journal.h"

namespace phnn {
namespace {

constexpr char kChecksumKey[] = " fnv1a64=";
constexpr char kFormatVersion[] = "1";

// %a and strtod follow LC_NUMERIC; the journal is always written and read in
// the "C" locale, whatever the program set with setlocale().
class CLocaleScope {
 public:
  CLocaleScope() {
    static const locale_t c_locale = newlocale(LC_ALL_MASK, "C", locale_t{});
    previous_ = uselocale(c_locale);
  }
  ~CLocaleScope() { uselocale(previous_); }
  CLocaleScope(const CLocaleScope&) = delete;
  CLocaleScope& operator=(const CLocaleScope&) = delete;

 private:
  locale_t previous_;
};

std::uint64_t bits_of(double v) {
  std::uint64_t b = 0;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

double from_bits(std::uint64_t b) {
  double v = 0;
  std::memcpy(&v, &b, sizeof v);
  return v;
}

constexpr std::uint64_t kQuietNan = 0x7ff8000000000000ULL;
constexpr std::uint64_t kNegativeQuietNan = 0xfff8000000000000ULL;

// Hex float (exact). %a cannot carry a NaN's sign and payload, so NaNs other
// than the two default quiet NaNs are written as nan_<IEEE bits>.
std::string format_double(double v) {
  if (std::isnan(v)) {
    const std::uint64_t b = bits_of(v);
    if (b == kQuietNan) return "nan";
    if (b == kNegativeQuietNan) return "-nan";
    return "nan_" + hex64(b);
  }
  char buf[40];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

bool parse_hex_u64(const std::string& text, std::uint64_t* out) {
  if (text.size() != 16) return false;
  std::uint64_t v = 0;
  for (char c : text) {
    int d = 0;
    if (c >= '0' && c <= '9') d = c - '0';
    else if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
    else return false;
    v = (v << 4) | static_cast<std::uint64_t>(d);
  }
  *out = v;
  return true;
}

bool parse_double(const std::string& text, double* out) {
  if (text == "nan") {
    *out = from_bits(kQuietNan);
    return true;
  }
  if (text == "-nan") {
    *out = from_bits(kNegativeQuietNan);
    return true;
  }
  if (text.compare(0, 4, "nan_") == 0) {
    std::uint64_t b = 0;
    if (!parse_hex_u64(text.substr(4), &b)) return false;
    *out = from_bits(b);
    return std::isnan(*out);
  }
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  *out = std::strtod(text.c_str(), &end);
  // ERANGE is fine for subnormals, which %a writes exactly.
  return end == text.c_str() + text.size() && !std::isnan(*out);
}

bool parse_int(const std::string& text, std::int64_t* out) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (errno != 0 || end != text.c_str() + text.size()) return false;
  *out = v;
  return true;
}

// Percent-encoding of every byte outside '!'..'~' and of '%' itself: the
// encoded text has no spaces (the field separator) and no newlines.
std::string escape(const std::string& text) {
  static const char kHex[] = "0123456789ABCDEF";
  std::string out;
  out.reserve(text.size());
  for (const char byte : text) {
    const auto c = static_cast<unsigned char>(byte);
    if (c > ' ' && c < 0x7f && c != '%') {
      out.push_back(static_cast<char>(c));
    } else {
      out.push_back('%');
      out.push_back(kHex[c >> 4]);
      out.push_back(kHex[c & 15]);
    }
  }
  return out;
}

bool unescape(const std::string& text, std::string* out) {
  out->clear();
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      out->push_back(text[i]);
      continue;
    }
    if (i + 2 >= text.size()) return false;
    int value = 0;
    for (std::size_t k = i + 1; k <= i + 2; ++k) {
      const char c = text[k];
      int d = 0;
      if (c >= '0' && c <= '9') d = c - '0';
      else if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
      else return false;
      value = value * 16 + d;
    }
    out->push_back(static_cast<char>(value));
    i += 2;
  }
  return true;
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  if (text.empty()) return parts;
  std::size_t begin = 0;
  while (true) {
    const std::size_t end = text.find(separator, begin);
    parts.push_back(text.substr(begin, end - begin));
    if (end == std::string::npos) return parts;
    begin = end + 1;
  }
}

std::string format_doubles(const std::vector<double>& values) {
  std::string out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) out.push_back(',');
    out += format_double(values[i]);
  }
  return out;
}

bool parse_doubles(const std::string& text, std::vector<double>* out) {
  out->clear();
  for (const std::string& part : split(text, ',')) {
    double v = 0;
    if (!parse_double(part, &v)) return false;
    out->push_back(v);
  }
  return true;
}

// A trace point is step:elapsed_s:train_loss:validation_loss:kappa:sigma_max:rho.
std::string format_trace(const std::vector<TracePoint>& trace) {
  std::string out;
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const TracePoint& t = trace[i];
    if (i) out.push_back(',');
    out += std::to_string(t.step) + ":" + format_double(t.elapsed_s) + ":" +
           format_double(t.train_loss) + ":" + format_double(t.validation_loss) + ":" +
           format_double(t.kappa) + ":" + format_double(t.sigma_max) + ":" +
           format_double(t.rho);
  }
  return out;
}

bool parse_trace(const std::string& text, std::vector<TracePoint>* out) {
  out->clear();
  for (const std::string& point : split(text, ',')) {
    const std::vector<std::string> f = split(point, ':');
    if (f.size() != 7) return false;
    TracePoint t;
    std::int64_t step = 0;
    if (!parse_int(f[0], &step) || !parse_double(f[1], &t.elapsed_s) ||
        !parse_double(f[2], &t.train_loss) || !parse_double(f[3], &t.validation_loss) ||
        !parse_double(f[4], &t.kappa) || !parse_double(f[5], &t.sigma_max) ||
        !parse_double(f[6], &t.rho)) {
      return false;
    }
    t.step = static_cast<int>(step);
    out->push_back(t);
  }
  return true;
}

// Comma-separated decimal integers ("" for none).
std::string format_ints(const std::vector<int>& values) {
  std::string out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    out += (i ? "," : "") + std::to_string(values[i]);
  }
  return out;
}

bool parse_ints(const std::string& text, std::vector<int>* out) {
  out->clear();
  if (text.empty()) return true;
  for (const std::string& item : split(text, ',')) {
    std::int64_t v = 0;
    if (!parse_int(item, &v) || v < 0 || v > 2147483647) return false;
    out->push_back(static_cast<int>(v));
  }
  return true;
}

// The checkpoint fields (TrainerOptions::checkpoints), written only when the
// run has checkpoints; a record without them (a run without checkpoints, or
// one written before they were journaled) reads as none.
void write_checkpoints(std::ostringstream& s, const RunResult& r) {
  if (r.checkpoint_steps.empty()) return;
  s << " checkpoint_steps=" << format_ints(r.checkpoint_steps)
    << " checkpoint_mse=" << format_doubles(r.checkpoint_mse)
    << " checkpoint_train_seconds=" << format_doubles(r.checkpoint_train_seconds);
}

bool read_checkpoints(std::map<std::string, std::string>& fields, RunResult* r) {
  if (fields.count("checkpoint_steps") == 0) return true;
  return parse_ints(fields["checkpoint_steps"], &r->checkpoint_steps) &&
         parse_doubles(fields["checkpoint_mse"], &r->checkpoint_mse) &&
         parse_doubles(fields["checkpoint_train_seconds"], &r->checkpoint_train_seconds) &&
         r->checkpoint_mse.size() == r->checkpoint_steps.size() &&
         r->checkpoint_train_seconds.size() == r->checkpoint_steps.size();
}

// The result columns of one slot (config/result_columns.h), " name=value"
// each; a column added later is left out while it is NaN (unknown), so a
// record of before it re-encodes to the same bytes.
void write_columns(std::ostringstream& s, const RunResult& r, JournalSlot slot) {
  for (const ResultColumn& c : result_columns()) {
    if (c.slot != slot) continue;
    if (c.type == ResultColumn::Type::kInt) {
      s << " " << c.name << "=" << c.get_int(r);
      continue;
    }
    const double v = c.get_double(r);
    if (c.added_later && bits_of(v) == kQuietNan) continue;
    s << " " << c.name << "=" << format_double(v);
  }
}

// Every result column from `fields`: integers within 0..highest; a column
// added later and missing reads NaN; any other missing column fails.
bool read_columns(std::map<std::string, std::string>& fields, RunResult* r) {
  for (const ResultColumn& c : result_columns()) {
    const auto it = fields.find(c.name);
    if (it == fields.end()) {
      if (!c.added_later) return false;
      c.set_double(*r, from_bits(kQuietNan));
    } else if (c.type == ResultColumn::Type::kInt) {
      std::int64_t v = 0;
      if (!parse_int(it->second, &v) || v < 0 || v > c.highest) return false;
      c.set_int(*r, v);
    } else {
      double v = 0;
      if (!parse_double(it->second, &v)) return false;
      c.set_double(*r, v);
    }
  }
  return true;
}

}  // namespace

namespace internal {

std::string encode_journal_record(const std::string& run_id, const RunResult& r,
                                  std::int64_t time_ns) {
  const CLocaleScope c_locale;
  std::ostringstream s;
  s << "run " << escape(run_id) << " v=" << kFormatVersion << " time=" << time_ns
    << " status=" << to_string(r.status) << " message=" << escape(r.message);
  write_columns(s, r, JournalSlot::kAfterMessage);
  s << " trajectory_errors=" << format_doubles(r.trajectory_errors);
  write_columns(s, r, JournalSlot::kAfterTrajectoryErrors);
  s << " trace=" << format_trace(r.trace);
  write_columns(s, r, JournalSlot::kAfterTrace);
  s << " figure_prediction_05=" << format_doubles(r.figure_prediction_05)
    << " figure_prediction_075=" << format_doubles(r.figure_prediction_075)
    << " figure_reference_05=" << format_doubles(r.figure_reference_05)
    << " figure_reference_075=" << format_doubles(r.figure_reference_075);
  write_checkpoints(s, r);
  if (!r.weights.empty()) s << " weights=" << format_doubles(r.weights);
  // The run's times (since 2026-11-28), so a row rewritten from its record
  // is the row as it was; a record without them reads as unknown times.
  if (!r.started_utc.empty()) s << " started=" << escape(r.started_utc);
  if (!r.finished_utc.empty()) s << " finished=" << escape(r.finished_utc);
  write_columns(s, r, JournalSlot::kAtEnd);
  const std::string body = s.str();
  return body + kChecksumKey + hex64(fnv1a64(body));
}

bool decode_journal_record(const std::string& line_in, std::string* run_id,
                           RunResult* result, std::int64_t* time_ns) {
  std::string line = line_in;
  if (!line.empty() && line.back() == '\n') line.pop_back();
  const std::size_t mark = line.rfind(kChecksumKey);
  if (line.compare(0, 4, "run ") != 0 || mark == std::string::npos) return false;
  std::uint64_t checksum = 0;
  const std::string body = line.substr(0, mark);
  if (!parse_hex_u64(line.substr(mark + sizeof(kChecksumKey) - 1), &checksum) ||
      checksum != fnv1a64(body)) {
    return false;
  }
  const std::vector<std::string> tokens = split(body, ' ');
  if (tokens.size() < 2 || !unescape(tokens[1], run_id) || run_id->empty()) return false;
  std::map<std::string, std::string> fields;
  for (std::size_t i = 2; i < tokens.size(); ++i) {
    const std::size_t eq = tokens[i].find('=');
    if (eq == std::string::npos) return false;
    fields[tokens[i].substr(0, eq)] = tokens[i].substr(eq + 1);
  }
  // Every field is required but the optional ones and the columns added
  // later; unknown fields (a later minor version) are ignored.
  for (const char* key : {"v", "time", "status", "message", "trajectory_errors", "trace",
                          "figure_prediction_05", "figure_prediction_075",
                          "figure_reference_05", "figure_reference_075"}) {
    if (fields.count(key) == 0) return false;
  }
  if (fields["v"] != kFormatVersion) return false;
  const CLocaleScope c_locale;
  RunResult r;
  try {
    r.status = parse_run_status(fields["status"]);
  } catch (const std::exception&) {
    return false;
  }
  if (!parse_int(fields["time"], time_ns) || !unescape(fields["message"], &r.message) ||
      !read_columns(fields, &r) ||
      !parse_doubles(fields["trajectory_errors"], &r.trajectory_errors) ||
      !parse_trace(fields["trace"], &r.trace) ||
      !parse_doubles(fields["figure_prediction_05"], &r.figure_prediction_05) ||
      !parse_doubles(fields["figure_prediction_075"], &r.figure_prediction_075) ||
      !parse_doubles(fields["figure_reference_05"], &r.figure_reference_05) ||
      !parse_doubles(fields["figure_reference_075"], &r.figure_reference_075) ||
      !read_checkpoints(fields, &r) ||
      (fields.count("weights") != 0 && !parse_doubles(fields["weights"], &r.weights)) ||
      (fields.count("started") != 0 && !unescape(fields["started"], &r.started_utc)) ||
      (fields.count("finished") != 0 && !unescape(fields["finished"], &r.finished_utc))) {
    return false;
  }
  *result = std::move(r);
  return true;
}

}  // namespace internal

}  // namespace phnn
