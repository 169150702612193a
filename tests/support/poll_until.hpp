#pragma once
// Waiting in a test for what another thread will do: by its state, polled up to a timeout, not
// by a fixed sleep, which a sanitizer's slower periods can outlast (a fixed 100 ms once gave 49 of
// the 50 stale periods a test asked for).

#include <chrono>
#include <thread>

namespace hapticsim::testing {

/** Polls `done` every 5 ms until it is true or `timeout` has passed; returns its last value. */
template <typename Predicate>
bool PollUntil(Predicate done, std::chrono::milliseconds timeout = std::chrono::seconds(2)) {
  const auto give_up = std::chrono::steady_clock::now() + timeout;
  while (!done() && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return done();
}

}  // namespace hapticsim::testing
