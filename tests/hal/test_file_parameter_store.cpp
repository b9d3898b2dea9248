// The parameter store in a Linux file: written to PATH.tmp and renamed, newest copy loaded,
// a cut or edited file refused with its reason.
#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include "hal/linux/file_parameter_store.hpp"

namespace {

namespace fs = std::filesystem;
using imd::hal::FileParameterStore;

class FileStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("imd_store_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    path_ = (dir_ / "motor.rec").string();
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<uint8_t> load(FileParameterStore& store) {
    std::array<uint8_t, 128> out{};
    const std::size_t n = store.load(out);
    return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)};
  }

  fs::path dir_;
  std::string path_;
};

std::vector<uint8_t> record(uint8_t seed) {
  std::vector<uint8_t> r(68);
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = static_cast<uint8_t>(seed + i);
  return r;
}

TEST_F(FileStoreTest, MissingFileIsNoRecordWithItsReason) {
  FileParameterStore store(path_);
  EXPECT_TRUE(load(store).empty());
  EXPECT_NE(store.last_error().find("No such file"), std::string::npos) << store.last_error();
}

TEST_F(FileStoreTest, SaveThenLoadInANewStore) {
  ASSERT_TRUE(FileParameterStore(path_).save(record(1)));
  ASSERT_TRUE(FileParameterStore(path_).save(record(2)));
  FileParameterStore store(path_);
  EXPECT_EQ(load(store), record(2));
  EXPECT_FALSE(fs::exists(path_ + ".tmp"));  // renamed, not left behind
}

TEST_F(FileStoreTest, ACutFileIsRefused) {
  ASSERT_TRUE(FileParameterStore(path_).save(record(1)));
  const auto size = fs::file_size(path_);
  for (const auto keep : {std::uintmax_t{0}, std::uintmax_t{11}, size / 2, size - 1}) {
    fs::resize_file(path_, keep);
    FileParameterStore store(path_);
    EXPECT_TRUE(load(store).empty()) << keep;
    EXPECT_NE(store.last_error().find("not a whole parameter record"), std::string::npos)
        << store.last_error();
    ASSERT_TRUE(FileParameterStore(path_).save(record(1)));
  }
}

TEST_F(FileStoreTest, AnEditedByteIsRefused) {
  ASSERT_TRUE(FileParameterStore(path_).save(record(1)));
  std::fstream f(path_, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(20);
  f.put(char(0x55));
  f.close();
  FileParameterStore store(path_);
  EXPECT_TRUE(load(store).empty());
}

TEST_F(FileStoreTest, ALeftoverTemporaryFileDoesNotMatter) {
  // A crash between the write of PATH.tmp and the rename: PATH still holds the old copy.
  ASSERT_TRUE(FileParameterStore(path_).save(record(1)));
  std::ofstream(path_ + ".tmp", std::ios::binary) << "half a record";
  FileParameterStore store(path_);
  EXPECT_EQ(load(store), record(1));
  ASSERT_TRUE(store.save(record(2)));
  EXPECT_EQ(load(store), record(2));
}

TEST_F(FileStoreTest, APathUnderAFileFailsTheSaveWithItsReasonAndKeepsTheOldCopy) {
  // Not a permission test (root writes anywhere): a regular file cannot hold a directory.
  ASSERT_TRUE(FileParameterStore(path_).save(record(1)));
  FileParameterStore store(path_ + "/motor.rec");
  EXPECT_FALSE(store.save(record(2)));
  EXPECT_NE(store.last_error().find("Not a directory"), std::string::npos) << store.last_error();
  FileParameterStore old(path_);
  EXPECT_EQ(load(old), record(1));
}

TEST_F(FileStoreTest, APathInAMissingDirectoryFailsTheSaveWithItsReason) {
  FileParameterStore store((dir_ / "no" / "such" / "motor.rec").string());
  EXPECT_FALSE(store.save(record(1)));
  EXPECT_NE(store.last_error().find("No such file"), std::string::npos) << store.last_error();
}

}  // namespace
