// include/phnn/data/counter_rng.h — counter-based random numbers: a value is a
// function of its keys (seed, system, trajectory, purpose), never of call order.
#pragma once

#include <cstdint>

namespace phnn {

/// SplitMix64 finalizer (Steele, Lea, Flood 2014): a bijective 64-bit mixer.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// Counter-based random stream: draw i is mix64(key + (i + 1) * golden), so a
/// stream is addressed by its key alone and never shares state with another.
/// Keys are derived from (data seed, system, trajectory index, purpose), so any
/// trajectory can be generated alone, bit-identically (docs/METHOD.md §2).
class CounterRng {
 public:
  /// Purposes of the streams of one trajectory.
  enum Stream : std::uint64_t {
    kInitialCondition = 1,
    kControl = 2,
    kTrainingPair = 3,
    kMeasurementNoise = 4,
    kBlockPairOrder = 5,   // recordings split in time blocks (data/measured.h)
    kBlockValidation = 6,
  };

  static CounterRng for_trajectory(std::uint64_t data_seed, int system_id,
                                   std::int64_t index, Stream stream) {
    std::uint64_t key = mix64(data_seed ^ 0x70686e6eULL);  // "phnn"
    key = mix64(key ^ (static_cast<std::uint64_t>(system_id) + 0x100));
    key = mix64(key ^ static_cast<std::uint64_t>(index));
    key = mix64(key ^ (static_cast<std::uint64_t>(stream) << 56));
    return CounterRng(key);
  }

  explicit CounterRng(std::uint64_t key) : key_(key) {}
  /// A stream resumed after `counter` draws (a saved training state).
  CounterRng(std::uint64_t key, std::uint64_t counter) : key_(key), counter_(counter) {}
  std::uint64_t key() const { return key_; }
  /// Draws taken so far.
  std::uint64_t counter() const { return counter_; }

  std::uint64_t next_u64() {
    ++counter_;
    return mix64(key_ + counter_ * 0x9E3779B97F4A7C15ULL);
  }
  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [0, n), n > 0 (Lemire's unbiased method).
  std::uint64_t below(std::uint64_t n) {
    for (;;) {
      const unsigned __int128 m =
          static_cast<unsigned __int128>(next_u64()) * n;
      const std::uint64_t low = static_cast<std::uint64_t>(m);
      if (low >= n || low >= (-n) % n) {
        return static_cast<std::uint64_t>(m >> 64);
      }
    }
  }

 private:
  std::uint64_t key_;
  std::uint64_t counter_ = 0;
};

}  // namespace phnn
