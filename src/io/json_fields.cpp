#include "io/json_fields.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>

#include "core/error.h"
#include "io/json_report.h"

namespace glint::io {

std::string key_path(const std::string& where, const std::string& key) {
  return where.empty() ? key : where + "." + key;
}

nlohmann::json JsonFields::read_document(const std::string& format, int version) const {
  nlohmann::json root = read_json(path_);
  if (!root.is_object()) fail("", "expected a JSON object at the top level");
  if (string(root, "format") != format) fail("format", fmt::format("expected \"{}\"", format));
  const nlohmann::json& found = member(root, "version");
  if (found != version)
    fail("version",
         fmt::format("unsupported version {} (this glint reads {})", found.dump(), version));
  return root;
}

void JsonFields::fail(const std::string& key, const std::string& reason) const {
  throw Error(path_, key, reason);
}

const nlohmann::json& JsonFields::member(const nlohmann::json& object, const std::string& key,
                                         const std::string& where) const {
  if (!object.is_object()) fail(where, "expected an object");
  const auto it = object.find(key);
  if (it == object.end()) fail(key_path(where, key), "missing key");
  return *it;
}

int JsonFields::integer(const nlohmann::json& object, const std::string& key,
                        const std::string& where) const {
  const nlohmann::json& value = member(object, key, where);
  if (!value.is_number_integer()) fail(key_path(where, key), "expected an integer");
  return value.get<int>();
}

std::vector<int> JsonFields::integers(const nlohmann::json& object, const std::string& key,
                                      const std::string& where) const {
  const nlohmann::json& array = member(object, key, where);
  if (!array.is_array()) fail(key_path(where, key), "expected an array of integers");
  std::vector<int> values;
  for (const auto& value : array) {
    if (!value.is_number_integer()) fail(key_path(where, key), "expected an array of integers");
    values.push_back(value.get<int>());
  }
  return values;
}

std::string JsonFields::string(const nlohmann::json& object, const std::string& key,
                               const std::string& where) const {
  const nlohmann::json& value = member(object, key, where);
  if (!value.is_string()) fail(key_path(where, key), "expected a string");
  return value.get<std::string>();
}

float JsonFields::finite_float(const nlohmann::json& value, const std::string& name) const {
  if (!value.is_number()) fail(name, "expected a number, got " + std::string(value.type_name()));
  // Doubles below 2^128 - 2^103 (FLT_MAX plus half an ulp) round to a finite float.
  static const double float_limit = std::ldexp(1.0, 128) - std::ldexp(1.0, 103);
  const double result = value.get<double>();
  if (!(std::fabs(result) < float_limit)) fail(name, "not a finite float");
  return static_cast<float>(result);
}

std::vector<float> JsonFields::floats(const nlohmann::json& object, const std::string& key,
                                      std::size_t count, const std::string& where) const {
  const std::string name = key_path(where, key);
  const nlohmann::json& array = member(object, key, where);
  if (!array.is_array()) fail(name, "expected an array of numbers");
  if (array.size() != count)
    fail(name, fmt::format("expected {} values, found {}", count, array.size()));
  std::vector<float> values(count);
  for (std::size_t i = 0; i < count; ++i)
    values[i] = finite_float(array[i], fmt::format("{}[{}]", name, i));
  return values;
}

double exact_float(float value) {
  return std::strtod(fmt::format("{:.9g}", value).c_str(), nullptr);
}

nlohmann::json exact_float_array(const float* values, std::size_t count) {
  nlohmann::json array = nlohmann::json::array();
  for (std::size_t i = 0; i < count; ++i) array.push_back(exact_float(values[i]));
  return array;
}

}  // namespace glint::io
