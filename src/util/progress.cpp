#include "util/progress.h"

#include "errors.h"

namespace lacuna {
namespace {
thread_local ProgressSink* t_current_sink = nullptr;
}  // namespace

ProgressSinkScope::ProgressSinkScope(ProgressSink* sink) : previous_(t_current_sink) { t_current_sink = sink; }

ProgressSinkScope::~ProgressSinkScope() { t_current_sink = previous_; }

ProgressSink* current_progress_sink() { return t_current_sink; }

void throw_if_cancelled(const ProgressSink* sink) {
  if (sink && sink->cancelled()) throw Cancelled("cancelled by the caller");
}

Progress::Progress(std::string stage, uint64_t total) : sink_(t_current_sink) {
  if (!sink_) return;
  throw_if_cancelled(sink_);
  sink_->begin(stage, total == 0 ? 1 : total);
}

Progress::~Progress() {
  if (sink_) sink_->end();
}

void Progress::advance(uint64_t n) {
  if (!sink_) return;
  sink_->advance(n);
  // Parallel loops pass the exception on to the thread that started them.
  throw_if_cancelled(sink_);
}

}  // namespace lacuna
