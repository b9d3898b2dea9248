#include "hal/linux/socketcand_session.hpp"

namespace imd::hal {
namespace {

constexpr std::string_view kOk = "< ok >";

}  // namespace

void SocketcandSession::answer_error(std::string text, std::string& replies) {
  ++errors_;
  replies += format_socketcand_error(text);
  new_errors_.push_back(std::move(text));
}

void SocketcandSession::receive(std::string_view bytes, std::string& replies,
                                std::vector<CanFrame>& frames) {
  using Kind = SocketcandCommand::Kind;
  new_errors_.clear();
  reader_.feed(bytes);
  while (const std::optional<SocketcandPiece> piece = reader_.next()) {
    if (piece->error) {
      answer_error(piece->text, replies);
      continue;
    }
    const SocketcandCommand command = parse_socketcand(piece->text);
    switch (command.kind) {
      case Kind::bad:
      case Kind::unsupported:
        answer_error(command.error, replies);
        break;
      case Kind::open:
        if (mode_ != Mode::no_bus) {
          answer_error("bus " + channel_ + " is already open", replies);
          break;
        }
        channel_ = command.channel;
        mode_ = Mode::bcm;
        replies += kOk;
        break;
      case Kind::rawmode:
      case Kind::bcmmode:
        if (mode_ == Mode::no_bus) {
          answer_error("no bus open: open one first, e.g. open can0", replies);
          break;
        }
        mode_ = command.kind == Kind::rawmode ? Mode::raw : Mode::bcm;
        replies += kOk;
        break;
      case Kind::echo:
        replies += "< echo >";
        break;
      case Kind::send:
        if (mode_ == Mode::no_bus) {
          answer_error("no bus open: open one first, e.g. open can0", replies);
          break;
        }
        frames.push_back(command.frame);
        break;
    }
  }
}

}  // namespace imd::hal
