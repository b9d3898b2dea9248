#pragma once
/// A lock-free ring buffer for one producer and one consumer, each in its own thread or
/// interrupt: the tick queues CAN frames that a sender thread (Linux) or the CAN interrupt
/// (MCU) takes. Wait-free on both sides, no allocation. Capacity is a power of two, and all
/// of it is usable: the indices run free and only their difference is compared.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace imd::hal {

template <typename T, std::size_t Capacity>
class SpscRing {
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "a power of two");

 public:
  /// Producer side. False if the ring is full (the item is not queued).
  bool try_push(const T& item) noexcept {
    const uint32_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) == Capacity) return false;
    items_[head & kMask] = item;
    head_.store(head + 1, std::memory_order_release);  // publishes the item
    return true;
  }

  /// Consumer side: the oldest item without taking it. nullptr if the ring is empty.
  const T* front() const noexcept {
    const uint32_t tail = tail_.load(std::memory_order_relaxed);
    if (head_.load(std::memory_order_acquire) == tail) return nullptr;
    return &items_[tail & kMask];
  }

  /// Consumer side: drops the oldest item (after front() returned it).
  void pop() noexcept {
    tail_.store(tail_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
  }

  /// Consumer side. False if the ring is empty.
  bool try_pop(T& item) noexcept {
    const T* oldest = front();
    if (oldest == nullptr) return false;
    item = *oldest;
    pop();
    return true;
  }

  /// Items queued; exact from either side's own thread, a snapshot from anywhere else.
  std::size_t size() const noexcept {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }
  static constexpr std::size_t capacity() noexcept { return Capacity; }

 private:
  static constexpr uint32_t kMask = Capacity - 1;
  // Free-running indices (wrapping at 2^32, a multiple of Capacity): full is head - tail ==
  // Capacity, so every slot is used. Each on its own cache line: no false sharing between
  // the two sides.
  alignas(64) std::atomic<uint32_t> head_{0};  ///< written by the producer only
  alignas(64) std::atomic<uint32_t> tail_{0};  ///< written by the consumer only
  std::array<T, Capacity> items_{};
};

}  // namespace imd::hal
