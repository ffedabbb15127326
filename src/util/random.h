// The project's own random generator, identical on every platform: xoshiro256** seeded through
// splitmix64. No std:: distributions (their output differs between standard libraries).
#pragma once

#include <cstdint>

namespace lacuna {

class Random {
 public:
  explicit Random(uint64_t seed);
  uint64_t next();   // 64 random bits
  double uniform();  // in [0, 1), from the top 53 bits

 private:
  uint64_t state_[4];
};

}  // namespace lacuna
