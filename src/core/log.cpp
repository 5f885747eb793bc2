#include "core/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>

#include "core/error.h"

namespace glint {

spdlog::logger& log() {
  static std::shared_ptr<spdlog::logger> logger = [] {
    // A plugin (the training module) has its own copy of this function but shares spdlog's
    // registry with the executable: it finds the executable's logger there.
    if (auto existing = spdlog::get("glint")) return existing;
    auto created = spdlog::stderr_color_mt("glint");
    created->set_pattern("[%^%l%$] %v");
    created->set_level(spdlog::level::info);
    return created;
  }();
  return *logger;
}

void set_log_level(const std::string& level) {
  const auto parsed = spdlog::level::from_str(level);
  if (parsed == spdlog::level::off && level != "off") {
    throw Error("", "--log-level",
                "unknown level '" + level + "' (trace, debug, info, warn, error, off)");
  }
  log().set_level(parsed);
}

}  // namespace glint
