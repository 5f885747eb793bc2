#pragma once
// Facts about the machine and the process that every benchmark report records.
#include <sys/resource.h>

#include <fstream>
#include <string>

namespace glint::bench {

// The CPU's "model name" from /proc/cpuinfo ("unknown" where there is none).
inline std::string cpu_model() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

// Peak resident memory of this process so far, MiB (getrusage's ru_maxrss is KiB on Linux).
inline double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

}  // namespace glint::bench
