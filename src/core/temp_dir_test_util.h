#pragma once
// A fresh folder per test, named by the test and the process (ctest -j2 runs tests at once), removed afterwards:
// the fixture core's file tests share.
#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace blurcue::test {

class TempDirTest : public ::testing::Test {
 protected:
  // `prefix` names the test file's kind of folder ("blurcue_atomic_").
  explicit TempDirTest(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (prefix_ + ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" + std::to_string(getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

}  // namespace blurcue::test
