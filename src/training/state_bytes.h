// src/training/state_bytes.h — a byte buffer for a cell's training state
// (private to src/training): plain values, vectors and tensors appended in
// order and read back in the same order. Touches no file.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <torch/torch.h>

namespace phnn {
namespace internal {

// Values in host byte order: a state is read back by the binary that wrote
// it (or one of the same build; the header's version says which layout).
class StateWriter {
 public:
  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  template <typename T>
  void put_vector(const std::vector<T>& values) {
    put<std::uint64_t>(values.size());
    for (const T& v : values) put(v);
  }
  void put_string(const std::string& text) {
    put<std::uint64_t>(text.size());
    bytes_.append(text);
  }
  // dtype, element count and the raw elements of a contiguous copy.
  void put_tensor(const torch::Tensor& t) {
    const torch::Tensor c = t.detach().contiguous();
    put<std::int32_t>(static_cast<std::int32_t>(c.scalar_type()));
    put<std::int64_t>(c.numel());
    bytes_.append(static_cast<const char*>(c.data_ptr()), c.numel() * c.element_size());
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

// Reads what StateWriter wrote; throws std::invalid_argument on a short
// buffer or a tensor of another type or size than the one it fills.
class StateReader {
 public:
  explicit StateReader(const std::string& bytes) : bytes_(bytes) {}

  template <typename T>
  T get() {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    T value;
    std::memcpy(&value, take(sizeof(T)), sizeof(T));
    return value;
  }
  template <typename T>
  std::vector<T> get_vector() {
    const auto n = get<std::uint64_t>();
    if (n > bytes_.size()) fail("vector length");
    std::vector<T> values(n);
    for (T& v : values) v = get<T>();
    return values;
  }
  std::string get_string() {
    const auto n = get<std::uint64_t>();
    if (n > bytes_.size()) fail("string length");
    return std::string(take(n), n);
  }
  // Copies the stored elements into `t` (same dtype and element count).
  void get_tensor(torch::Tensor t) {
    const auto type = get<std::int32_t>();
    const auto numel = get<std::int64_t>();
    if (type != static_cast<std::int32_t>(t.scalar_type()) || numel != t.numel()) {
      fail("tensor of another type or size");
    }
    const auto size = static_cast<std::size_t>(numel * t.element_size());
    const char* data = take(size);
    torch::NoGradGuard no_grad;
    // Through an aligned buffer: the bytes sit at any offset of the state.
    torch::Tensor stored = torch::empty(t.sizes(), t.options().requires_grad(false));
    std::memcpy(stored.data_ptr(), data, size);
    t.copy_(stored);
  }
  bool at_end() const { return pos_ == bytes_.size(); }

 private:
  const char* take(std::size_t n) {
    if (n > bytes_.size() - pos_) fail("the state ends early");
    const char* p = bytes_.data() + pos_;
    pos_ += n;
    return p;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw std::invalid_argument("training state does not fit this cell (" + what + " at byte " +
                                std::to_string(pos_) + ")");
  }
  const std::string& bytes_;
  std::size_t pos_ = 0;
};

}  // namespace internal
}  // namespace phnn
