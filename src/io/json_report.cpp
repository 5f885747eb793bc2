#include "io/json_report.h"

#include <fstream>

#include "core/error.h"
#include "io/atomic_file.h"

namespace glint::io {

void write_json(const std::string& path, const nlohmann::json& value) {
  AtomicFile file(path, false);
  file.stream() << value.dump(2) << '\n';
  file.commit();
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream stream(path);
  if (!stream) throw Error(path, "", "cannot open the file");
  try {
    return nlohmann::json::parse(stream);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error(path, "byte " + std::to_string(e.byte), "not valid JSON: " + std::string(e.what()));
  }
}

}  // namespace glint::io
