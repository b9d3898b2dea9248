// The parameter store on a flash page pair: load picks the newest whole copy, and a power loss
// at any byte of a save leaves the old record or the new one loadable, never a corrupt one.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "hal/storage/crc32.hpp"
#include "hal/storage/page_pair_store.hpp"
#include "hal/storage/stored_slot.hpp"
#include "hal_sim/sim_flash_pages.hpp"

namespace {

using imd::hal::PagePairStore;
using imd::sim::SimFlashPages;
constexpr std::size_t kMax = 96;
using Store = PagePairStore<kMax>;

std::vector<uint8_t> record(uint8_t seed, std::size_t n = 68) {
  std::vector<uint8_t> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = static_cast<uint8_t>(seed * 31 + i * 7);
  return r;
}

std::vector<uint8_t> load(SimFlashPages& flash) {
  Store store(flash);  // a new store: the board after a power-up
  std::array<uint8_t, kMax> out{};
  const std::size_t n = store.load(out);
  return {out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n)};
}

TEST(Crc32, CheckValue) {
  const std::string s = "123456789";
  EXPECT_EQ(imd::hal::crc32({reinterpret_cast<const uint8_t*>(s.data()), s.size()}), 0xCBF43926u);
}

TEST(PagePairStore, EmptyFlashHasNoRecord) {
  SimFlashPages flash;
  EXPECT_TRUE(load(flash).empty());
}

TEST(PagePairStore, LoadsTheNewestOfManySaves) {
  SimFlashPages flash;
  for (uint8_t i = 1; i <= 5; ++i) {
    Store store(flash);
    ASSERT_TRUE(store.save(record(i)));
    EXPECT_EQ(load(flash), record(i)) << int(i);
  }
}

TEST(PagePairStore, RejectsARecordLargerThanItsBuffer) {
  SimFlashPages flash;
  Store store(flash);
  EXPECT_FALSE(store.save(record(1, kMax + 1)));
  EXPECT_TRUE(load(flash).empty());
}

TEST(PagePairStore, ACorruptNewestCopyMakesTheOlderOneWin) {
  SimFlashPages flash;
  Store(flash).save(record(1));  // page 0
  Store(flash).save(record(2));  // page 1
  // A bit of the newest copy lost after the write (wear, disturb): flash loses charge, so the
  // copy is rebuilt on fresh pages with one data bit cleared.
  std::vector<uint8_t> page0(flash.page_bytes()), page1(flash.page_bytes());
  flash.read(0, 0, page0);
  flash.read(1, 0, page1);
  ASSERT_NE(page1[20] & 0x10, 0) << "pick a set bit";
  page1[20] &= static_cast<uint8_t>(~0x10);
  SimFlashPages worn;
  worn.program(0, 0, page0);
  worn.program(1, 0, page1);
  EXPECT_EQ(load(worn), record(1));
}

// Every byte operation of a save (the erase of the older page, the body, the commit word) is
// a point where the power can go. After it, the next boot must load the previous record or the
// new one, exactly; which one depends only on whether the commit word was written whole. The
// commit word is the first half of the last 8-byte unit; its second half is 0xFF, which
// programming leaves as erased, so the last 4 byte operations do not change what loads.
TEST(PagePairStore, PowerLossAtEveryByteOfASaveLeavesTheOldOrTheNewRecord) {
  for (const int saves_before : {1, 2, 3}) {  // the target page: 1 (empty), 0 or 1 (older copy)
    SimFlashPages probe;
    for (int i = 0; i < saves_before; ++i) Store(probe).save(record(uint8_t(i + 1)));
    const std::size_t before = probe.operations();
    ASSERT_TRUE(Store(probe).save(record(9)));
    const std::size_t save_ops = probe.operations() - before;
    const std::vector<uint8_t> old_record = record(uint8_t(saves_before));
    int old_loaded = 0, new_loaded = 0;
    for (std::size_t cut = 0; cut <= save_ops; ++cut) {
      SimFlashPages flash;
      for (int i = 0; i < saves_before; ++i) Store(flash).save(record(uint8_t(i + 1)));
      flash.cut_power_after(cut);
      const bool saved = Store(flash).save(record(9));
      flash.restore_power();
      const std::vector<uint8_t> loaded = load(flash);
      const bool committed = cut + 4 >= save_ops;
      if (loaded == record(9)) {
        EXPECT_TRUE(committed) << "cut after " << cut << " of " << save_ops;
        ++new_loaded;
      } else {
        EXPECT_FALSE(committed) << "cut after " << cut << " of " << save_ops;
        ASSERT_EQ(loaded, old_record) << "cut after " << cut << " of " << save_ops
                                      << " byte operations, " << saves_before << " saves before";
        ++old_loaded;
      }
      EXPECT_EQ(saved, cut == save_ops) << cut;  // a cut save reports its failure
      // The store still works after the loss: the next save lands and loads.
      ASSERT_TRUE(Store(flash).save(record(10)));
      ASSERT_EQ(load(flash), record(10)) << cut;
    }
    EXPECT_EQ(new_loaded, 5) << saves_before;
    EXPECT_EQ(old_loaded + new_loaded, int(save_ops) + 1) << saves_before;
  }
}

TEST(StoredSlot, SequenceComparisonSurvivesTheWrap) {
  EXPECT_TRUE(imd::hal::newer(1, 0));
  EXPECT_TRUE(imd::hal::newer(0, 0xFFFFFFFFu));
  EXPECT_FALSE(imd::hal::newer(0xFFFFFFFFu, 0));
  EXPECT_FALSE(imd::hal::newer(5, 5));
}

}  // namespace
