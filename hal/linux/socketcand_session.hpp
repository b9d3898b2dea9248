#pragma once
/// One socketcand client's conversation, without the socket: what it sent in, what to answer,
/// which frames go to the drive. The modes are socketcand's: after `< hi >` the client must
/// `< open BUS >` (any name: the drive has one bus), which enters BCM mode; `< rawmode >` then
/// makes every frame of the drive go to the client. `< send ... >` works in BCM and raw mode,
/// `< echo >` in both; the broadcast manager's own commands are not served. Every message that
/// cannot be obeyed is answered `< error ... >` and counted; the session goes on.
/// I/O thread only (it allocates).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "hal/can_bus.hpp"
#include "hal/linux/socketcand_text.hpp"

namespace imd::hal {

class SocketcandSession {
 public:
  enum class Mode { no_bus, bcm, raw };
  static constexpr std::string_view kGreeting = "< hi >";

  /// Takes received bytes: appends the answers to `replies` and the frames the client sent to
  /// `frames`.
  void receive(std::string_view bytes, std::string& replies, std::vector<CanFrame>& frames);

  Mode mode() const noexcept { return mode_; }
  /// Whether the drive's frames go to this client.
  bool raw() const noexcept { return mode_ == Mode::raw; }
  const std::string& channel() const noexcept { return channel_; }
  /// Messages answered `< error ... >`.
  uint64_t errors() const noexcept { return errors_; }
  /// Their texts (without `< error` and `>`) from the last receive(), for the log.
  const std::vector<std::string>& new_errors() const noexcept { return new_errors_; }

 private:
  void answer_error(std::string text, std::string& replies);

  SocketcandReader reader_;
  Mode mode_ = Mode::no_bus;
  std::string channel_;
  uint64_t errors_ = 0;
  std::vector<std::string> new_errors_;
};

}  // namespace imd::hal
