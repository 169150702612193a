#pragma once

#include <string>
#include <vector>

namespace hapticsim::testing {

struct CommandResult {
  int exit_status = -1;
  std::string out;  ///< standard output
  std::string err;  ///< standard error
};

/** Runs a program (no shell) and collects its exit status and both output streams. */
CommandResult RunCommand(const std::vector<std::string>& argv);

/** A program running beside the test (a daemon), its stderr and stdout going to a file. */
class BackgroundProcess {
 public:
  BackgroundProcess(const std::vector<std::string>& argv, const std::string& log_path);
  /** Kills it (SIGKILL) if it still runs. */
  ~BackgroundProcess();
  void Signal(int signal) const;
  /** Exit status once it ends (128 + signal when killed), or -1 after `timeout_s`. */
  int Wait(double timeout_s);
  bool running();
  std::string Log() const;
  int pid() const { return pid_; }

 private:
  int pid_ = -1;
  int status_ = -1;
  std::string log_path_;
};

}  // namespace hapticsim::testing
