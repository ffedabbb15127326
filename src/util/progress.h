// Progress and cancellation of long stages. The library only reports: a front end passes a
// ProgressSink (the command line's draws bars on a terminal), and stages report to the sink that
// is current on the thread that started them. Nothing here draws.
#pragma once

#include <cstdint>
#include <string>

namespace lacuna {

// What a front end implements to follow the stages of a call and to stop it. begin() and end()
// come from the thread that runs the call, in nested pairs; advance() from any thread.
class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  // A stage of `total` steps starts (a stage inside another ends before it).
  virtual void begin(const std::string& stage, uint64_t total) = 0;
  // `n` more steps of the innermost stage are done.
  virtual void advance(uint64_t n) = 0;
  // The innermost stage ends.
  virtual void end() = 0;
  // Whether the caller wants the work stopped; stages then throw Cancelled at their next start or
  // step. Called from any thread, after every advance().
  virtual bool cancelled() const { return false; }
};

// Makes `sink` (may be null: no reports) the one stages started on this thread report to, until
// the scope ends; the previous one is current again afterwards.
class ProgressSinkScope {
 public:
  explicit ProgressSinkScope(ProgressSink* sink);
  ~ProgressSinkScope();
  ProgressSinkScope(const ProgressSinkScope&) = delete;
  ProgressSinkScope& operator=(const ProgressSinkScope&) = delete;

 private:
  ProgressSink* previous_;
};

// The sink current on this thread, or null.
ProgressSink* current_progress_sink();

// Throws Cancelled when `sink` is set and asks to stop.
void throw_if_cancelled(const ProgressSink* sink);

// One stage's progress, reported to the sink current on the thread that creates it: begin on
// construction (throwing Cancelled first when the sink asks to stop), end on destruction.
// advance() may be called from any thread; it throws Cancelled when the sink asks to stop.
class Progress {
 public:
  Progress(std::string stage, uint64_t total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(uint64_t n = 1);

 private:
  ProgressSink* sink_;
};

}  // namespace lacuna
