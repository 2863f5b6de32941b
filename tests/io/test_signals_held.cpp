// The one commit guard of the output writers (src/io/signals_held.hpp), used by OutputSet::commit and by the Zarr
// store's commit: a signal that comes while it is held — to the committing thread or to any other — waits until
// the guarded section is complete, then ends the process as it would have. (The Zarr writer's own guard blocked
// the signal in its thread only: a signal taken by another thread ended the process in the middle of the commit.)
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "../../src/io/signals_held.hpp"
#include "afmkit/io/output.hpp"

namespace fs = std::filesystem;

namespace {

/// Runs `body` in a child process with afmkit's signal handling; its wait status.
template <class Body>
int in_child(Body&& body) {
  const pid_t child = ::fork();
  if (child == 0) {
    afmkit::io::remove_temporaries_on_signal();
    body();
    std::_Exit(0);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return status;
}

}  // namespace

TEST(SignalsHeld, ASignalToAnyThreadWaitsForTheGuardedSectionThenEndsTheProcess) {
  const fs::path marker = fs::temp_directory_path() / ("afmkit_signals_held_" + std::to_string(::getpid()));
  fs::remove(marker);
  for (const bool other_thread : {true, false}) {
    const int status = in_child([&] {
      std::thread helper;  // a thread with the signals not blocked: the kernel may give it the signal
      {
        afmkit::io::detail::SignalsHeld held;
        if (other_thread)
          helper = std::thread([] { ::kill(::getpid(), SIGTERM); });  // delivered to the helper: noted there
        else
          ::kill(::getpid(), SIGTERM);  // blocked in this thread: pending
        if (helper.joinable()) helper.join();
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        std::ofstream(marker) << "complete";  // the guarded section ends
      }
      std::this_thread::sleep_for(std::chrono::seconds(5));  // (the signal ends the process before this)
      std::_Exit(3);
    });
    ASSERT_TRUE(WIFSIGNALED(status)) << "other thread " << other_thread << ": exit status " << WEXITSTATUS(status);
    EXPECT_EQ(WTERMSIG(status), SIGTERM);
    EXPECT_TRUE(fs::exists(marker)) << "other thread " << other_thread << ": the guarded section was cut short";
    fs::remove(marker);
  }
}

TEST(SignalsHeld, WithoutAGuardASignalEndsTheProcessAtOnce) {
  const int status = in_child([] {
    ::kill(::getpid(), SIGTERM);
    std::this_thread::sleep_for(std::chrono::seconds(5));
    std::_Exit(3);
  });
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
}
