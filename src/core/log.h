#pragma once
// glint's logger (spdlog, to stderr). Levels: trace, debug, info, warn, error.
#include <spdlog/spdlog.h>

#include <string>

namespace glint {

spdlog::logger& log();
// Sets the level by name; throws glint::Error for an unknown name.
void set_log_level(const std::string& level);

}  // namespace glint
