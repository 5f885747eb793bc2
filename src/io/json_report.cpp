#include "io/json_report.h"

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/file_bytes.h"

namespace glint::io {

void write_json(const std::string& path, const nlohmann::json& value) {
  std::string text;
  try {
    text = value.dump(2) + '\n';
  } catch (const nlohmann::json::exception& e) {  // e.g. a string that is not UTF-8
    throw Error(path, "", std::string("cannot write as JSON: ") + e.what());
  }
  AtomicFile file(path, false);
  file.stream() << text;
  file.commit();
}

nlohmann::json read_json(const std::string& path) {
  const std::string text = read_file_bytes(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error(path, "byte " + std::to_string(e.byte), std::string("not valid JSON: ") + e.what());
  } catch (const nlohmann::json::exception& e) {  // e.g. a number beyond double's range
    throw Error(path, "", std::string("not valid JSON: ") + e.what());
  }
}

}  // namespace glint::io
