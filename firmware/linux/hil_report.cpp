#include "firmware/linux/hil_report.hpp"

#include <fmt/format.h>

#include "hal/linux/socketcan_bus.hpp"

namespace imd::firmware {
namespace {

/// The non-empty bins, {"us": count} (the full histogram is mostly zeros).
nlohmann::json bins_json(const hal::LatencyHistogram& h) {
  nlohmann::json bins = nlohmann::json::object();
  for (std::size_t us = 0; us < h.bins().size(); ++us) {
    if (h.bins()[us] != 0) bins[std::to_string(us)] = h.bins()[us];
  }
  return bins;
}

}  // namespace

nlohmann::json histogram_json(const hal::LatencyHistogram& h, uint32_t period_ns) {
  return {{"samples", h.count()},
          {"p50_us", h.quantile_us(0.50)},
          {"p99_us", h.quantile_us(0.99)},
          {"p99_9_us", h.quantile_us(0.999)},
          {"max_us", double(h.max_ns()) / 1000.0},
          {"mean_us", h.mean_ns() / 1000.0},
          {"at_least_one_period", h.count_at_least_us(period_ns / 1000)},
          {"bins_us", bins_json(h)}};
}

nlohmann::json report_json(const HilRunFacts& f) {
  nlohmann::json j = {
      {"scenario", f.scenario},
      {"stop_reason", f.stop_reason},
      {"period_us", double(f.period_ns) / 1000.0},
      {"wall_s", f.wall_s},
      {"ticks", f.ticks},
      {"simulated_s", double(f.ticks) * double(f.period_ns) * 1e-9},
      {"missed_periods", f.missed_periods},
      {"sched_fifo", f.realtime},
      {"fifo_priority", f.fifo_priority},
      {"warnings", f.warnings},
      {"drive",
       {{"state", f.state},
        {"first_fault", f.first_fault},
        {"precision", f.precision},
        {"tick_overruns", f.drive_overruns},
        {"telemetry_dropped", f.telemetry_dropped}}},
  };
  if (f.wakeup != nullptr) j["wakeup_latency"] = histogram_json(*f.wakeup, f.period_ns);
  if (f.execution != nullptr) j["execution_time"] = histogram_json(*f.execution, f.period_ns);
  j["can"] = {{"iface", f.can_iface}};
  if (f.can) {
    j["can"]["sent"] = f.can->sent;
    j["can"]["received"] = f.can->received;
    j["can"]["rx_dropped"] = f.can->rx_dropped;
    j["can"]["tx_retries"] = f.can->tx_retries;
    j["can"]["error_frames"] = f.can->error_frames;
    j["can"]["bus_off_events"] = f.can->bus_off_events;
    j["can"]["last_error"] = hal::describe_error_class(f.can->last_error_class);
  }
  if (f.socketcand) {
    j["can"]["socketcand"] = {{"clients", f.socketcand->clients},
                              {"clients_refused", f.socketcand->clients_refused},
                              {"dropped_no_client", f.socketcand->dropped_no_client},
                              {"client_errors", f.socketcand->client_errors},
                              {"filtered", f.socketcand->filtered},
                              {"clients_dropped", f.socketcand->clients_dropped}};
  }
  return j;
}

std::string report_text(const HilRunFacts& f) {
  std::string text = fmt::format(
      "drive_hil: stopped ({}) after {:.3f} s: {} ticks ({:.3f} s simulated), {} missed periods\n",
      f.stop_reason, f.wall_s, f.ticks, double(f.ticks) * double(f.period_ns) * 1e-9,
      f.missed_periods);
  text += fmt::format("drive_hil: drive {}, first fault {}, {} tick overruns\n", f.state,
                      f.first_fault, f.drive_overruns);
  if (f.wakeup != nullptr && f.execution != nullptr) {
    const hal::LatencyHistogram& w = *f.wakeup;
    const hal::LatencyHistogram& e = *f.execution;
    text += fmt::format(
        "drive_hil: wake-up latency p50 {:.0f} us, p99 {:.0f} us, p99.9 {:.0f} us, max {:.0f} us; "
        "tick p50 {:.0f} us, max {:.0f} us ({})\n",
        w.quantile_us(0.5), w.quantile_us(0.99), w.quantile_us(0.999), double(w.max_ns()) / 1e3,
        e.quantile_us(0.5), double(e.max_ns()) / 1e3,
        f.realtime ? fmt::format("SCHED_FIFO {}", f.fifo_priority) : "normal scheduler");
  }
  if (f.can) {
    text += fmt::format(
        "drive_hil: CAN {}: {} frames sent, {} received, {} dropped on receive, {} error frames "
        "(last: {}), {} bus-off, {} telemetry frames dropped\n",
        f.can_iface, f.can->sent, f.can->received, f.can->rx_dropped, f.can->error_frames,
        hal::describe_error_class(f.can->last_error_class), f.can->bus_off_events,
        f.telemetry_dropped);
  }
  if (f.socketcand) {
    text += fmt::format(
        "drive_hil: socketcand: {} clients ({} refused busy), {} frames dropped with no client, "
        "{} client messages answered with an error\n",
        f.socketcand->clients, f.socketcand->clients_refused, f.socketcand->dropped_no_client,
        f.socketcand->client_errors);
  }
  return text;
}

}  // namespace imd::firmware
