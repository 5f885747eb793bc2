#pragma once
// Reading and writing the fields of glint's JSON files (models, datasets): every read failure
// is one glint::Error naming the file and the key path ("layers[2].bias[5]"), and floats are
// written with 9 significant digits so that reading them back gives the same float.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace glint::io {

// The key path of `key` inside the object at key path `where` ("" at the top level).
std::string key_path(const std::string& where, const std::string& key);

class JsonFields {
 public:
  explicit JsonFields(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& reason) const;

  // Reads the file, which must hold a JSON object whose "format" is `format` and whose
  // "version" is `version`.
  nlohmann::json read_document(const std::string& format, int version) const;

  // object[key]; `where` is the key path of `object` ("" at the top level).
  const nlohmann::json& member(const nlohmann::json& object, const std::string& key,
                               const std::string& where = "") const;
  int integer(const nlohmann::json& object, const std::string& key,
              const std::string& where = "") const;
  std::string string(const nlohmann::json& object, const std::string& key,
                     const std::string& where = "") const;
  // An array of integers (any length).
  std::vector<int> integers(const nlohmann::json& object, const std::string& key,
                            const std::string& where = "") const;
  // A number that is finite as a float; `name` is its key path.
  float finite_float(const nlohmann::json& value, const std::string& name) const;
  // An array of exactly `count` finite floats.
  std::vector<float> floats(const nlohmann::json& object, const std::string& key, std::size_t count,
                            const std::string& where = "") const;

 private:
  std::string path_;
};

// The double closest to the float's 9-significant-digit decimal (what the JSON writer prints).
double exact_float(float value);
nlohmann::json exact_float_array(const float* values, std::size_t count);
inline nlohmann::json exact_float_array(const std::vector<float>& values) {
  return exact_float_array(values.data(), values.size());
}

}  // namespace glint::io
