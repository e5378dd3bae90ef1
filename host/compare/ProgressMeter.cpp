#include "compare/ProgressMeter.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>

namespace misalloc {

ProgressMeter::ProgressMeter(int totalSteps, std::FILE* stream)
    : total_(std::max(1, totalSteps)),
      stream_(stream),
      terminal_(::isatty(::fileno(stream)) != 0),
      start_(std::chrono::steady_clock::now()) {}

ProgressMeter::~ProgressMeter() {
  if (barShown_) std::fputc('\n', stream_);
}

std::string ProgressMeter::eta() const {
  if (done_ == 0) return "?";
  double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  int left = int(elapsed / done_ * (total_ - done_) + 0.5);
  return left >= 60 ? fmt::format("{}m{:02}s", left / 60, left % 60) : fmt::format("{}s", left);
}

void ProgressMeter::clearBar() {
  if (barShown_) std::fputs("\r\033[K", stream_);
  barShown_ = false;
}

void ProgressMeter::step(const std::string& label) {
  ++done_;
  if (!terminal_) {
    std::fputs(fmt::format("[{}/{}] {} (left: {})\n", done_, total_, label, eta()).c_str(), stream_);
  } else {
    constexpr int kWidth = 30;
    int filled = done_ * kWidth / total_;
    clearBar();
    std::fputs(fmt::format("[{}{}] {}/{} {} | left {}", std::string(filled, '#'), std::string(kWidth - filled, '.'),
                           done_, total_, label, eta())
                   .c_str(),
               stream_);
    barShown_ = true;
  }
  std::fflush(stream_);
}

void ProgressMeter::note(const std::string& message) {
  clearBar();
  std::fputs((message + "\n").c_str(), stream_);
  std::fflush(stream_);
}

}  // namespace misalloc
