#pragma once
/// @file A small reader of fuzzer bytes (numbers, choices, text), usable with or without
/// libFuzzer (the replay driver builds the fuzzers with any compiler). Reading past the end
/// gives zeros, so every input decodes to something.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

namespace strata::fuzz {

class ByteReader {
  public:
    ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

    bool empty() const { return pos_ >= size_; }
    std::size_t remaining() const { return pos_ < size_ ? size_ - pos_ : 0; }

    std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
    std::uint32_t u32() {
        std::uint32_t v = 0;
        for (int i = 0; i < 4; ++i) v = (v << 8) | byte();
        return v;
    }
    /// An integer in [lo, hi] (hi - lo < 2^32).
    std::size_t range(std::size_t lo, std::size_t hi) {
        const std::size_t span = hi - lo + 1;
        const std::uint32_t raw = span <= 256 ? byte() : u32();
        return lo + static_cast<std::size_t>(raw) % span;
    }
    bool boolean() { return (byte() & 1U) != 0; }
    /// A fraction in [0, 1] with 256 steps.
    double unit() { return static_cast<double>(byte()) / 255.0; }
    /// Any double bit pattern (NaN, inf, subnormals included).
    double raw_double() {
        std::uint64_t bits = (static_cast<std::uint64_t>(u32()) << 32) | u32();
        double v = 0.0;
        std::memcpy(&v, &bits, sizeof v);
        return v;
    }
    /// The rest of the input as text.
    std::string rest() {
        std::string s;
        if (pos_ < size_) s.assign(reinterpret_cast<const char*>(data_ + pos_), size_ - pos_);
        pos_ = size_;
        return s;
    }

  private:
    const std::uint8_t* data_;
    std::size_t size_;
    std::size_t pos_ = 0;
};

}  // namespace strata::fuzz
