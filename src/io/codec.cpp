#include "io/codec.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace glint::io {
namespace {

template <class T>
T load(const char* at, bool swap) {
  std::array<char, sizeof(T)> raw;
  std::memcpy(raw.data(), at, sizeof(T));
  if (swap) std::reverse(raw.begin(), raw.end());
  return std::bit_cast<T>(raw);
}

template <class T>
bool whole_in_range(double value) {
  return value == std::floor(value) && value >= double(std::numeric_limits<T>::lowest()) &&
         value <= double(std::numeric_limits<T>::max());
}

// Doubles below this magnitude round to a finite float (FLT_MAX plus half an ulp).
constexpr double kFloatRoundingLimit = 0x1.ffffffp127;

bool is_space(char c) {
  return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\v' || c == '\f';
}

}  // namespace

Scalar scalar_of(const AttributeColumn& column) { return static_cast<Scalar>(column.index()); }

AttributeColumn make_column(Scalar type, std::size_t n) {
  switch (type) {
    case Scalar::int8:
      return std::vector<std::int8_t>(n);
    case Scalar::uint8:
      return std::vector<std::uint8_t>(n);
    case Scalar::int16:
      return std::vector<std::int16_t>(n);
    case Scalar::uint16:
      return std::vector<std::uint16_t>(n);
    case Scalar::int32:
      return std::vector<std::int32_t>(n);
    case Scalar::uint32:
      return std::vector<std::uint32_t>(n);
    case Scalar::float32:
      return std::vector<float>(n);
    case Scalar::float64:
      return std::vector<double>(n);
  }
  return {};
}

char* column_bytes(AttributeColumn& column) {
  return std::visit([](auto& values) { return reinterpret_cast<char*>(values.data()); }, column);
}

const char* column_bytes(const AttributeColumn& column) {
  return std::visit([](const auto& values) { return reinterpret_cast<const char*>(values.data()); },
                    column);
}

double decode(Scalar type, const char* at, bool swap) {
  switch (type) {
    case Scalar::int8:
      return load<std::int8_t>(at, swap);
    case Scalar::uint8:
      return load<std::uint8_t>(at, swap);
    case Scalar::int16:
      return load<std::int16_t>(at, swap);
    case Scalar::uint16:
      return load<std::uint16_t>(at, swap);
    case Scalar::int32:
      return load<std::int32_t>(at, swap);
    case Scalar::uint32:
      return load<std::uint32_t>(at, swap);
    case Scalar::float32:
      return load<float>(at, swap);
    case Scalar::float64:
      return load<double>(at, swap);
  }
  return 0.0;
}

void copy_value(const char* from, char* to, std::size_t size, bool swap) {
  if (swap) {
    std::reverse_copy(from, from + size, to);
  } else {
    std::memcpy(to, from, size);
  }
}

bool fits(Scalar type, double value) {
  switch (type) {
    case Scalar::int8:
      return whole_in_range<std::int8_t>(value);
    case Scalar::uint8:
      return whole_in_range<std::uint8_t>(value);
    case Scalar::int16:
      return whole_in_range<std::int16_t>(value);
    case Scalar::uint16:
      return whole_in_range<std::uint16_t>(value);
    case Scalar::int32:
      return whole_in_range<std::int32_t>(value);
    case Scalar::uint32:
      return whole_in_range<std::uint32_t>(value);
    case Scalar::float32:
      return !std::isfinite(value) || std::fabs(value) < kFloatRoundingLimit;
    case Scalar::float64:
      return true;
  }
  return false;
}

void store(AttributeColumn& column, std::size_t i, double value) {
  std::visit(
      [&](auto& values) {
        values[i] = static_cast<std::ranges::range_value_t<decltype(values)>>(value);
      },
      column);
}

void append_value(std::string& out, const AttributeColumn& column, std::size_t i) {
  char buffer[32];
  char* end = std::visit(
      [&](const auto& values) {
        return std::to_chars(buffer, buffer + sizeof buffer, values[i]).ptr;
      },
      column);
  out.append(buffer, end);
}

void append_value(std::string& out, float value) {
  char buffer[32];
  out.append(buffer, std::to_chars(buffer, buffer + sizeof buffer, value).ptr);
}

bool parse_number(std::string_view token, double& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  return error == std::errc() && end == token.data() + token.size();
}

bool parse_count(std::string_view token, std::size_t& value) {
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  return error == std::errc() && end == token.data() + token.size();
}

std::string lowercase(std::string_view text) {
  std::string result(text);
  for (char& c : result) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return result;
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  Tokens tokens(line.data(), line.data() + line.size());
  for (std::string_view word = tokens.next(); !word.empty(); word = tokens.next()) {
    words.push_back(word);
  }
  return words;
}

void flush_buffer(std::string& buffer, std::ostream& out, std::size_t threshold) {
  if (buffer.size() < threshold) return;
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  buffer.clear();
}

std::string_view Tokens::next() {
  while (at_ < end_ && is_space(*at_)) ++at_;
  const char* begin = at_;
  while (at_ < end_ && !is_space(*at_)) ++at_;
  return {begin, static_cast<std::size_t>(at_ - begin)};
}

}  // namespace glint::io
