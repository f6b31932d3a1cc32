#include "core/json.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>

#include "core/error.h"

namespace lumislab {
namespace {

std::string MessageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return "";
}

TEST(JsonTest, NamesFileFieldExpectedAndGot) {
  const JsonDocument doc = JsonDocument::Parse(
      R"({"setup": {"grid": {"nu": -3, "h": "x"}, "list": [1, 2]}})", "dataset.json");
  EXPECT_EQ(MessageOf([&] { doc.root()["setup"]["grid"]["nu"].IntAtLeast(1); }),
            "dataset.json: setup.grid.nu: expected integer >= 1, got -3");
  EXPECT_EQ(MessageOf([&] { doc.root()["setup"]["grid"]["h"].Positive(); }),
            "dataset.json: setup.grid.h: expected number, got \"x\"");
  EXPECT_EQ(MessageOf([&] { doc.root()["setup"]["grid"]["nv"]; }),
            "dataset.json: setup.grid.nv: expected a value, got nothing (missing)");
  EXPECT_EQ(MessageOf([&] { doc.root()["setup"]["list"][2]; }),
            "dataset.json: setup.list[2]: expected a value, got nothing (missing)");
  EXPECT_EQ(MessageOf([&] { doc.root()["setup"]["list"].Numbers(3); }),
            "dataset.json: setup.list: expected array of 3 numbers, got [1,2]");
}

TEST(JsonTest, TypedAccessAndDefaults) {
  const JsonDocument doc =
      JsonDocument::Parse(R"({"a": 1.5, "b": 3, "s": "bell", "t": true})", "x.json");
  const JsonView r = doc.root();
  EXPECT_DOUBLE_EQ(r["a"].Number(), 1.5);
  EXPECT_EQ(r["b"].IntIn(1, 4), 3);
  EXPECT_EQ(r["s"].OneOf({"bell", "box"}), "bell");
  EXPECT_TRUE(r["t"].Bool());
  EXPECT_EQ(r.IntOr("missing", 7), 7);
  EXPECT_DOUBLE_EQ(r.NumberOr("a", 0), 1.5);
  EXPECT_THROW(r["a"].Int(), Error);  // 1.5 is not an integer
  EXPECT_NE(MessageOf([&] { r["s"].OneOf({"box"}); }).find("expected one of box"),
            std::string::npos);
}

TEST(JsonTest, ParseErrorsAndMissingFilesAreBadInput) {
  EXPECT_NE(MessageOf([] {
              JsonDocument::Parse("{not json", "scene.json");
            }).find("scene.json: not valid JSON"),
            std::string::npos);
  EXPECT_NE(MessageOf([] {
              JsonDocument::Load("/nonexistent/dataset.json");
            }).find("/nonexistent/dataset.json"),
            std::string::npos);
}

// JSON holds only UTF-8 text: a Latin-1 file name in a document is exit 2 naming the file, the
// field and the value (odd bytes as \xHH), not the JSON library's exception; UTF-8 passes.
TEST(JsonTest, TextThatIsNotUtf8IsRefusedNamingTheField) {
  nlohmann::json j = {{"photo_folder", "../caf\xc3\xa9"}, {"photos", {{{"file", "a.png"}}}}};
  EXPECT_NE(DumpJson(j, "ds/dataset.json").find("caf\xc3\xa9"), std::string::npos);
  j["photos"][0]["file"] = "caf\xe9.png";
  try {
    DumpJson(j, "ds/dataset.json");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_STREQ(e.what(),
                 "ds/dataset.json: photos[0].file: expected UTF-8 text (JSON holds nothing else: "
                 "rename the file or folder, e.g. with convmv -f latin1 -t utf8), got "
                 "\"caf\\xE9.png\"");
  }
  const std::string dir = ::testing::TempDir() + "/lumislab_json_utf8";
  std::filesystem::create_directories(dir);
  EXPECT_THROW(WriteJsonAtomically(dir + "/x.json", j), Error);
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.json"));
  std::filesystem::remove_all(dir);
}

TEST(JsonTest, SchemaVersionIsChecked) {
  EXPECT_NE(MessageOf([] {
              JsonDocument::Parse("{}", "s.json").CheckSchemaVersion(1);
            }).find("s.json: schema_version"),
            std::string::npos);
  EXPECT_NE(MessageOf([] {
              JsonDocument::Parse(R"({"schema_version": 9})", "s.json").CheckSchemaVersion(1);
            }).find("newer"),
            std::string::npos);
  EXPECT_NO_THROW(JsonDocument::Parse(R"({"schema_version": 1})", "s.json").CheckSchemaVersion(1));
}

// Hostile files are refused before parsing: deep nesting (nlohmann recurses while parsing and
// destroying), huge texts, and paths that are no regular file (a FIFO would block the read).
TEST(JsonTest, RefusesDeepLargeAndNonRegularInputs) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_NE(MessageOf([&] {
              JsonDocument::Parse(deep, "deep.json");
            }).find("deep.json: expected arrays and objects nested at most 64 deep"),
            std::string::npos);
  // In a string, brackets do not nest.
  EXPECT_NO_THROW(JsonDocument::Parse("{\"s\": \"" + std::string(1000, '[') + "\"}", "s.json"));
  EXPECT_NE(MessageOf([] {
              JsonDocument::Parse(std::string(kMaxJsonBytes + 1, ' '), "big.json");
            }).find("big.json: expected a JSON text of at most"),
            std::string::npos);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("lumislab_json_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir / "folder.json");
  const std::string fifo = (dir / "fifo.json").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(MessageOf([&] { JsonDocument::Load(fifo); }).find("not a regular file"),
            std::string::npos);
  EXPECT_NE(MessageOf([&] {
              JsonDocument::Load((dir / "folder.json").string());
            }).find("not a regular file"),
            std::string::npos);
  EXPECT_NE(MessageOf([&] {
              JsonDocument::Load((dir / "missing.json").string());
            }).find("missing.json: JSON file not found"),
            std::string::npos);
  EXPECT_NE(MessageOf([] {
              JsonDocument::Parse("{\"a\": x}", "bad.json");
            }).find("bad.json: not valid JSON: parse error at line 1, column 7"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lumislab
