#pragma once

// The threads of a running process, as /proc shows them: found by name (pthread_setname_np),
// and the nice value each runs at.
#include <sys/types.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hapticsim::testing {

// The kernel thread id of process `pid`'s thread named `name` (-1: none).
inline pid_t ThreadOf(int pid, const std::string& name) {
  const std::filesystem::path tasks = "/proc/" + std::to_string(pid) + "/task";
  for (const auto& task : std::filesystem::directory_iterator(tasks)) {
    std::ifstream comm(task.path() / "comm");
    std::string comm_name;
    std::getline(comm, comm_name);
    if (comm_name == name) return static_cast<pid_t>(std::stol(task.path().filename().string()));
  }
  return -1;
}

// The nice value thread `tid` of process `pid` runs at (proc(5): stat's 19th field), or 99 if
// it cannot be read.
inline int NiceOf(int pid, pid_t tid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/task/" + std::to_string(tid) + "/stat");
  std::string text;
  std::getline(stat, text);
  const std::size_t name_end = text.rfind(')');  // the name may hold spaces
  if (name_end == std::string::npos) return 99;
  std::istringstream fields(text.substr(name_end + 2));
  std::string field;
  for (int i = 3; i <= 19 && fields >> field; ++i) {
    if (i == 19) return std::stoi(field);
  }
  return 99;
}

}  // namespace hapticsim::testing
