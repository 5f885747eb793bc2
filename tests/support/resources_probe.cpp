// A loadable module that links glint_core, as the Python extension module does: the resources
// test copies it into a made-up prefix's lib/python3/dist-packages/glint/ and asks it where
// glint's files are, from there.
#include <cstring>
#include <string>

#include "core/error.h"
#include "core/resources.h"

// Writes code_location() and models_directory() (or the error) as "location\nmodels" into
// `text` (`size` bytes); plain C so that no exception or std type crosses the module boundary.
extern "C" __attribute__((visibility("default"))) void glint_resources_probe(char* text,
                                                                             std::size_t size) {
  std::string answer = glint::code_location().string() + "\n";
  try {
    answer += glint::models_directory().string();
  } catch (const glint::Error& e) {
    answer += e.what();
  }
  std::strncpy(text, answer.c_str(), size - 1);
  text[size - 1] = '\0';
}
