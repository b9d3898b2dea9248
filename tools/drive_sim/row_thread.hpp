#pragma once
/// Rows handed to a second thread in blocks, so that what is done with them (drive_sim's CSV
/// formatting and writing) overlaps the simulation that makes them. The rows are copied into
/// one of kBlocks blocks of kRowsPerBlock; a full block goes to the worker, which takes them in
/// order. When every block is with the worker the producer waits: memory stays bounded (about
/// 400 kB for drive_sim's rows) and the order of the rows is kept, so the worker sees exactly
/// the sequence of rows it would have seen called directly. One lock per block, not per row.
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace imd::tools {

template <typename Row>
class RowThread {
 public:
  static constexpr std::size_t kRowsPerBlock = 256;
  static constexpr std::size_t kBlocks = 4;

  /// `consume` runs on the worker thread, once per block, in order.
  explicit RowThread(std::function<void(const Row* rows, std::size_t count)> consume)
      : consume_(std::move(consume)), rows_(kBlocks * kRowsPerBlock) {
    worker_ = std::thread([this] { work(); });
  }
  RowThread(const RowThread&) = delete;
  RowThread& operator=(const RowThread&) = delete;
  ~RowThread() { drain(); }

  /// Copies the row; hands its block over when full (and waits for a free one if none is).
  void push(const Row& row) {
    rows_[filling_ * kRowsPerBlock + filled_] = row;
    if (++filled_ == kRowsPerBlock) hand_over();
  }

  /// Hands over the partial block and returns when the worker has consumed every row.
  void drain() {
    if (!worker_.joinable()) return;
    if (filled_ > 0) hand_over();
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    work_ready_.notify_one();
    worker_.join();
  }

 private:
  void hand_over() {
    std::unique_lock<std::mutex> lock(mutex_);
    counts_[filling_] = filled_;
    ++queued_;
    work_ready_.notify_one();
    block_free_.wait(lock, [this] { return queued_ < kBlocks; });
    filling_ = (filling_ + 1) % kBlocks;
    filled_ = 0;
  }

  void work() {
    std::size_t next = 0;
    for (;;) {
      std::size_t count = 0;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        work_ready_.wait(lock, [this] { return queued_ > 0 || stopping_; });
        if (queued_ == 0) return;  // stopping, and nothing left
        count = counts_[next];
      }
      consume_(&rows_[next * kRowsPerBlock], count);
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        --queued_;
      }
      block_free_.notify_one();
      next = (next + 1) % kBlocks;
    }
  }

  std::function<void(const Row*, std::size_t)> consume_;
  std::vector<Row> rows_;
  std::size_t filling_ = 0, filled_ = 0;  ///< the producer's block and its rows (its own)
  std::mutex mutex_;
  std::condition_variable work_ready_, block_free_;
  std::size_t counts_[kBlocks] = {};  ///< rows in each handed-over block (under mutex_)
  std::size_t queued_ = 0;            ///< blocks with the worker (under mutex_)
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace imd::tools
