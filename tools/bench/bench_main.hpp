#pragma once
// The benchmarks' main: runs them with a console reporter that also fails loudly. A benchmark
// that measured nothing, or not the state it means to measure, calls State::SkipWithError (the
// checks are in each benchmark); any such run makes the program exit with status 1, so that
// tools/run_benchmarks.sh stops instead of reporting a figure of nothing. It also prints the
// ratios of the pairs a program declares (a method against its baseline, measured in the same
// run).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace imd::bench {

/// Ratios to print: time of `baseline` over time of `candidate`, for every run whose name
/// starts with `baseline` (the rest of the name, e.g. "/100" or "_mean", must match).
struct RatioPair {
  std::string baseline, candidate;
};

class CheckingReporter final : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      if (run.error_occurred) {
        ++errors_;
        std::fprintf(stderr, "benchmark %s failed: %s\n", run.benchmark_name().c_str(),
                     run.error_message.c_str());
      } else if (run.iterations > 0 && is_time(run)) {
        seconds_[run.benchmark_name()] = run.GetAdjustedRealTime();
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
  int errors() const noexcept { return errors_; }
  void print_ratios(const std::vector<RatioPair>& pairs) const {
    for (const RatioPair& pair : pairs) {
      for (const auto& [name, time] : seconds_) {
        if (name.rfind(pair.baseline, 0) != 0) continue;
        const std::string rest = name.substr(pair.baseline.size());
        const auto candidate = seconds_.find(pair.candidate + rest);
        if (candidate == seconds_.end() || candidate->second <= 0.0) continue;
        std::printf("ratio %s%s / %s%s = %.2f (the candidate is %.2fx faster)\n",
                    pair.baseline.c_str(), rest.c_str(), pair.candidate.c_str(), rest.c_str(),
                    time / candidate->second, time / candidate->second);
      }
    }
  }

 private:
  /// A time to compare: a run, or the mean or median of repetitions (their standard deviation
  /// and coefficient of variation are spreads, whose ratio says nothing of speed).
  static bool is_time(const Run& run) {
    return run.run_type != Run::RT_Aggregate || run.aggregate_name == "mean" ||
           run.aggregate_name == "median";
  }

  std::map<std::string, double> seconds_;
  int errors_ = 0;
};

/// main() of a benchmark program: 0 when every benchmark it ran succeeded, 1 when one failed.
/// (A filter that selects none of a program's benchmarks is not a failure: run_benchmarks.sh
/// passes one filter to every program.)
inline int run_benchmarks(int argc, char** argv, const std::vector<RatioPair>& pairs = {}) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  CheckingReporter reporter;
  const std::size_t ran = benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  reporter.print_ratios(pairs);
  if (ran == 0) std::fprintf(stderr, "%s: no benchmark matched the filter\n", argv[0]);
  return reporter.errors() != 0 ? 1 : 0;
}

}  // namespace imd::bench
