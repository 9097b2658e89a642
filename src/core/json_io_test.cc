#include <unistd.h>
#include "core/json_io.h"

#include <sys/stat.h>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"

namespace blurcue {
namespace {

namespace fs = std::filesystem;

fs::path TempFile(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / ("blurcue-json-io-test-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary) << text;
  return dir / name;
}

// The one-line message of the Error(kInput) that reading `path` throws ("" and a failure when it throws none).
std::string JsonReadError(const fs::path& path) {
  try {
    ReadJsonFile(path);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput) << e.what();
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(path.string(), 0), 0u) << message;  // names the file first
    return message;
  }
  ADD_FAILURE() << path << " was read";
  return "";
}

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(ReadJsonFile, ReadsAValidFile) {
  EXPECT_EQ(ReadJsonFile(TempFile("ok.json", R"({"a": [1, 2.5, "x"]})"))["a"][1], 2.5);
}

TEST(ReadJsonFile, DeepNestingIsRefusedBeforeParsing) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  const std::string message = JsonReadError(TempFile("deep.json", deep));
  EXPECT_TRUE(Contains(message, "nested deeper than 64 levels at line 1, column 65")) << message;
}

TEST(ReadJsonFile, DeepNestingAfterAByteOrderMarkIsRefusedToo) {
  const std::string deep = "\xEF\xBB\xBF" + std::string(100000, '[') + std::string(100000, ']');
  EXPECT_TRUE(Contains(JsonReadError(TempFile("bom-deep.json", deep)), "nested deeper than 64 levels"));
}

TEST(ReadJsonFile, BracketsInsideStringsDoNotCountAsNesting) {
  const Json j = ReadJsonFile(TempFile("brackets.json", "{\"a\": \"" + std::string(1000, '[') + "\\\"{\"}"));
  EXPECT_EQ(j["a"].get<std::string>().size(), 1002u);
}

TEST(ReadJsonFile, NestingUpToTheLimitIsRead) {
  EXPECT_NO_THROW(ReadJsonFile(TempFile("64.json", std::string(64, '[') + std::string(64, ']'))));
  EXPECT_TRUE(Contains(JsonReadError(TempFile("65.json", std::string(65, '[') + std::string(65, ']'))), "deeper"));
}

TEST(ReadJsonFile, BinaryFileIsASyntaxErrorNotADepthError) {
  const std::string message = JsonReadError(TempFile("image.png", "\x89PNG\r\n" + std::string(200, '[')));
  EXPECT_TRUE(Contains(message, "not valid JSON: parse error at line 1, column 1")) << message;
}

TEST(ReadJsonFile, KeyGivenTwiceIsRefusedNamingWhere) {
  const std::string message = JsonReadError(TempFile(
      "twice.json", R"({"a": [1, {"b": 2}, {"c": {"d": 1, "e/f": 2, "e/f": 3}}], "g": 1})"));
  EXPECT_TRUE(Contains(message, ": /a/2/c/e~1f: is given twice in the same object")) << message;
  // The same key in different objects is not a repeat.
  EXPECT_NO_THROW(ReadJsonFile(TempFile("not-twice.json", R"({"a": {"x": 1}, "b": {"x": 2}, "x": [{"x": 3}]})")));
}

TEST(ReadJsonFile, NumberBeyondDoubleNamesWhereItIs) {
  const std::string message = JsonReadError(TempFile("huge.json", "{\n  \"speed_cm_s\": 1e400\n}"));
  EXPECT_TRUE(Contains(message, "at line 2, column 17")) << message;
  EXPECT_TRUE(Contains(message, "1e400")) << message;
}

TEST(ReadJsonFile, SyntaxErrorNamesLineAndColumn) {
  const std::string message = JsonReadError(TempFile("syntax.json", "{\n  \"a\": [1 2]\n}"));
  EXPECT_TRUE(Contains(message, "not valid JSON: parse error at line 2, column 11")) << message;
}

TEST(ReadJsonFile, MissingFileIsAnInputError) {
  EXPECT_TRUE(Contains(JsonReadError(fs::temp_directory_path() / "blurcue-no-such.json"), "cannot open file"));
}

TEST(ReadJsonFile, FolderIsRefused) {
  EXPECT_TRUE(Contains(JsonReadError(fs::temp_directory_path()), "is a folder"));
}

TEST(ReadJsonFile, DeviceIsRefused) {
  EXPECT_TRUE(Contains(JsonReadError("/dev/zero"), "not a regular file"));
}

TEST(ReadJsonFile, FifoIsRefusedWithoutWaitingForAWriter) {
  const fs::path fifo = fs::temp_directory_path() / ("blurcue-json-io-test-" + std::to_string(::getpid())) / "fifo.json";
  fs::create_directories(fifo.parent_path());
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_TRUE(Contains(JsonReadError(fifo), "not a regular file"));
  fs::remove(fifo);
}

TEST(ReadJsonFile, ProcFileThatCannotBeReadIsAnInputError) {
  EXPECT_TRUE(Contains(JsonReadError("/proc/self/mem"), "cannot read file"));
}

TEST(ReadJsonFile, FileOverTheCapIsRefused) {
  const std::string message = JsonReadError(TempFile("big.json", "[" + std::string(kMaxJsonBytes, ' ') + "]"));
  EXPECT_TRUE(Contains(message, "at most 16 MiB")) << message;
}

TEST(RequireInt, NumberBeyondIntIsRefusedNotWrapped) {
  const Json j = Json::parse(R"({"w": 4294968444, "n": -4294967296, "ok": 1148})");
  EXPECT_THROW(RequireInt(j, "w", "f"), Error);
  EXPECT_THROW(RequireInt(j, "n", "f"), Error);
  EXPECT_EQ(RequireInt(j, "ok", "f"), 1148);
}

}  // namespace
}  // namespace blurcue
