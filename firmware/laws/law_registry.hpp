#pragma once
/// The drive's control laws, all of the image's built at start-up (a law is chosen at run time,
/// over CAN, while the drive is idle). This is the one place where laws are registered: a new
/// law is one entry in `AllLaws` below, in ControllerKind order (firmware/drive_config.hpp; its
/// name comes from the CAN protocol's value table, firmware/protocol/messages.hpp), and one
/// case in `law_in_image` (firmware/image_features.hpp). docs/architecture.md, "How to add a
/// control law".
#include <array>
#include <iterator>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>

#include "firmware/drive_config.hpp"
#include "firmware/image_features.hpp"
#include "firmware/laws/control_law.hpp"
#include "firmware/laws/dsmc_law.hpp"
#include "firmware/laws/ifoc_law.hpp"
#include "firmware/laws/iol_law.hpp"
#include "firmware/laws/law_context.hpp"
#include "firmware/protocol/messages.hpp"

namespace imd::firmware {

template <typename T>
using AllLaws = std::tuple<DsmcLaw<T>, IolLaw<T>, IfocLaw<T>>;

/// The laws of a tuple that this image carries, in their order.
template <typename Tuple>
struct InImage;
template <typename... L>
struct InImage<std::tuple<L...>> {
  using type = decltype(std::tuple_cat(
      std::declval<std::conditional_t<law_in_image(L::kKind), std::tuple<L>, std::tuple<>>>()...));
};
template <typename T>
using Laws = typename InImage<AllLaws<T>>::type;

/// The law of this name ("dsmc", "iol", "ifoc": the CAN protocol's value table, which the DBC
/// carries); false for no such law. Construction and configuration only.
inline bool controller_named(std::string_view name, ControllerKind& kind) noexcept {
  for (const protocol::ValueName& v : protocol::kControllerValues) {
    if (name == v.name) {
      kind = static_cast<ControllerKind>(v.raw);
      return true;
    }
  }
  return false;
}
static_assert(std::size(protocol::kControllerValues) == kControllerCount,
              "every law has its name in the protocol's value table");

template <typename T>
class LawRegistry {
 public:
  static constexpr std::size_t kCount = std::tuple_size_v<Laws<T>>;
  static_assert(std::tuple_size_v<AllLaws<T>> == kControllerCount, "one law per ControllerKind");

  explicit LawRegistry(const LawContext& c) : laws_(make(c, std::make_index_sequence<kCount>{})) {
    check_order(std::make_index_sequence<kControllerCount>{});
    std::apply([this](auto&... law) { ((table_[static_cast<int>(law.kKind)] = &law), ...); },
               laws_);
  }
  LawRegistry(const LawRegistry&) = delete;
  LawRegistry& operator=(const LawRegistry&) = delete;

  /// Every law takes over the state of its counterpart in `old` (the same motor but for its
  /// rotor resistance). Tick context.
  void continue_from(const LawRegistry& old) noexcept {
    std::apply([&](auto&... law) { std::apply([&](const auto&... was) { (law.continue_from(was), ...); }, old.laws_); }, laws_);
  }

  /// The law `kind`, which this image carries (law_in_image).
  ControlLaw<T>& law(ControllerKind kind) noexcept { return *table_[static_cast<int>(kind)]; }
  const ControlLaw<T>& law(ControllerKind kind) const noexcept {
    return *table_[static_cast<int>(kind)];
  }

 private:
  using Table = std::array<ControlLaw<T>*, kControllerCount>;  ///< null: not in this image

  template <std::size_t... I>
  static Laws<T> make(const LawContext& c, std::index_sequence<I...>) {
    return Laws<T>(std::tuple_element_t<I, Laws<T>>(c)...);
  }
  template <std::size_t... I>
  static constexpr void check_order(std::index_sequence<I...>) {
    static_assert(
        ((static_cast<std::size_t>(std::tuple_element_t<I, AllLaws<T>>::kKind) == I) && ...),
        "AllLaws lists the laws in ControllerKind order");
  }

  Laws<T> laws_;
  Table table_{};
};

}  // namespace imd::firmware
