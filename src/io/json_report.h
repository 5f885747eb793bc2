#pragma once
// JSON reports and small JSON files (models, run summaries), written atomically and pretty
// printed with two-space indentation.
#include <nlohmann/json.hpp>
#include <string>

namespace glint::io {

void write_json(const std::string& path, const nlohmann::json& value);
// Parses a JSON file; throws glint::Error naming the file and the parse position on failure.
nlohmann::json read_json(const std::string& path);

}  // namespace glint::io
