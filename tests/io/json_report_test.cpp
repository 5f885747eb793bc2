#include "io/json_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::error_of;
using test::scratch;
using test::write_text;
using ::testing::HasSubstr;

TEST(Json, WritesPrettyTwoSpaceJsonEndingInANewline) {
  const std::string path = scratch("report.json");
  write_json(path, {{"points", 3}, {"name", "cube"}});
  EXPECT_EQ(test::read_text(path), "{\n  \"name\": \"cube\",\n  \"points\": 3\n}\n");
  EXPECT_EQ(read_json(path)["points"], 3);
}

TEST(Json, ParseErrorsNameTheFileAndTheByte) {
  const std::string path = scratch("broken.json");
  write_text(path, "{\"points\": 3,");
  const Error e = error_of([&] { read_json(path); });
  EXPECT_EQ(e.file(), path);
  EXPECT_EQ(e.element(), "byte 14");
  EXPECT_THAT(e.reason(), HasSubstr("not valid JSON"));
}

TEST(Json, ANumberBeyondDoubleNamesTheFile) {
  const std::string path = scratch("overflow.json");
  write_text(path, "{\"position\": [0, 1e999, 0]}");
  const Error e = error_of([&] { read_json(path); });
  EXPECT_EQ(e.file(), path);
  EXPECT_THAT(e.reason(), HasSubstr("not valid JSON"));
}

TEST(Json, MissingFileAndUnwritableValues) {
  EXPECT_THAT(error_of([] { read_json(scratch("missing.json")); }).reason(),
              HasSubstr("cannot open the file"));
  const std::string path = scratch("bad_utf8.json");
  EXPECT_THAT(error_of([&] { write_json(path, std::string("\xff")); }).reason(),
              HasSubstr("cannot write as JSON"));
}

}  // namespace
}  // namespace glint::io
