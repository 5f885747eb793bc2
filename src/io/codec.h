#pragma once
// Internal to io: scalar types, binary and text encoding, ascii tokens and buffered output shared
// by the PLY, PCD and text readers and writers.
#include <cstddef>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "core/point_cloud.h"

namespace glint::io {

// The attribute scalar types, in the order of AttributeColumn's alternatives.
enum class Scalar { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

inline std::size_t size_of(Scalar type) {
  constexpr std::size_t kSizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[static_cast<int>(type)];
}

Scalar scalar_of(const AttributeColumn& column);
AttributeColumn make_column(Scalar type, std::size_t n);
// A column's storage, for copying binary values straight in or out.
char* column_bytes(AttributeColumn& column);
const char* column_bytes(const AttributeColumn& column);

// The binary value of `type` at `at`, byte order reversed when `swap`, as double.
double decode(Scalar type, const char* at, bool swap);
// Copies `size` bytes, reversing their order when `swap`.
void copy_value(const char* from, char* to, std::size_t size, bool swap);
// Whether `value` is exactly representable in `type`: integers must be whole and in range;
// floats must be in range or non-finite.
bool fits(Scalar type, double value);
// column[i] = value, converted to the column's type (`value` must fit it).
void store(AttributeColumn& column, std::size_t i, double value);
// Appends one value in the shortest text that reads back to the same value.
void append_value(std::string& out, const AttributeColumn& column, std::size_t i);
void append_value(std::string& out, float value);

// A whole token as a number: decimal or scientific, optional sign, "nan", "inf".
bool parse_number(std::string_view token, double& value);
// A whole token as a non-negative integer (a count).
bool parse_count(std::string_view token, std::size_t& value);
std::string lowercase(std::string_view text);
// The whitespace-separated words of a line.
std::vector<std::string_view> split_words(std::string_view line);

// Writes `buffer` to `out` and empties it once it holds at least `threshold` bytes (0: always),
// so that large outputs are produced in chunks rather than built whole in memory.
void flush_buffer(std::string& buffer, std::ostream& out, std::size_t threshold = 1 << 20);

// Walks the whitespace-separated tokens of an ascii body.
class Tokens {
 public:
  Tokens(const char* begin, const char* end) : at_(begin), end_(end) {}
  // The next token; empty when the data is exhausted.
  std::string_view next();
  std::size_t remaining() const { return static_cast<std::size_t>(end_ - at_); }

 private:
  const char* at_;
  const char* end_;
};

}  // namespace glint::io
