// gyrodrift: the command line tool. Subcommands live in *_command.cc and register themselves.
#include <fmt/core.h>
#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <thread>

#include "cli_util.h"
#include "command.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/version.h"
#include "gyrodrift/io/files.h"

namespace gyrodrift::cli {
std::vector<Command>& Commands() {
  static std::vector<Command> commands;
  return commands;
}
}  // namespace gyrodrift::cli

namespace {

// Ctrl-C, a kill or a closed terminal: one thread of its own takes these signals (every other
// thread blocks them, so no handler runs amid a write), removes the temporaries of the writes
// under way once a set being placed is whole, then ends the process by the signal, as it would
// have ended (the exit status says so). A signal the caller ignores (nohup's SIGHUP) stays ignored.
void EndOnSignals() {
  sigset_t set;
  ::sigemptyset(&set);
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction current {};
    if (::sigaction(signal_number, nullptr, &current) == 0 && current.sa_handler == SIG_IGN) {
      continue;
    }
    ::sigaddset(&set, signal_number);
  }
  // Before any other thread starts, so that every thread inherits the mask.
  if (::pthread_sigmask(SIG_BLOCK, &set, nullptr) != 0) return;  // the defaults then stand
  std::thread([set] {
    int signal_number = 0;
    if (::sigwait(&set, &signal_number) != 0) return;
    gyrodrift::io::RemoveTemporariesForExit();
    ::signal(signal_number, SIG_DFL);
    sigset_t taken;
    ::sigemptyset(&taken);
    ::sigaddset(&taken, signal_number);
    ::pthread_sigmask(SIG_UNBLOCK, &taken, nullptr);
    ::raise(signal_number);
    std::_Exit(128 + signal_number);  // not reached: the signal ended the process
  }).detach();
}

}  // namespace

int main(int argc, char** argv) {
  EndOnSignals();
  CLI::App app{
      "gyrodrift: model and compensate the thermal drift of gyroscopes (MS-ELM, Chen & Cui 2016).",
      "gyrodrift"};
  app.footer(
      "Example:\n"
      "  gyrodrift simulate --duration 8h -o fog.csv           # a thermal-chamber log with truth\n"
      "  gyrodrift decompose fog.csv --column rate_dph --method beemdan -o imfs.csv\n"
      "  gyrodrift allan fog.csv --column rate_dph --rate-hz 1 -o adev.csv\n"
      "  gyrodrift fit fog.csv --target rate_dph --temperature temperature_c --mode compensate \\\n"
      "      -o model.json && gyrodrift compensate model.json other_run.csv -o compensated.csv\n"
      "  gyrodrift export model.json --format c -o gyro_comp.h  # the model as C99 for firmware\n"
      "  gyrodrift demo                                        # everything, with an HTML report\n"
      "Run 'gyrodrift SUBCOMMAND --help' for each subcommand. Exit codes: 0 ok, 2 usage,\n"
      "3 data, 4 file I/O, 5 a fleet unit did not pass (calibrate), 1 internal error\n"
      "(see docs/errors.md).");
  app.set_version_flag("--version", std::string("gyrodrift ") + gyrodrift::kVersion);
  app.require_subcommand(1);
  auto& commands = gyrodrift::cli::Commands();
  std::sort(commands.begin(), commands.end(),
            [](const auto& a, const auto& b) { return a.order < b.order; });
  for (auto& command : commands) command.setup(app);
  gyrodrift::cli::RefuseEmptyValues(app);
  // A misspelt command would otherwise read "A subcommand is required".
  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) {
      names += (names.empty() ? "" : ", ") + sub->get_name();
      known = known || sub->get_name() == argv[1];
    }
    if (!known) {
      fmt::print(stderr, "gyrodrift: error: unknown command '{}' (commands: {})\n", argv[1],
                 names);
      return gyrodrift::ExitCode(gyrodrift::ErrorKind::kUsage);
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ConversionError& e) {
    fmt::print(stderr, "gyrodrift: error: {}\n", gyrodrift::cli::ConversionMessage(app, e));
    return gyrodrift::ExitCode(gyrodrift::ErrorKind::kUsage);
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr, "gyrodrift: error: {}\n", e.what());
    return gyrodrift::ExitCode(gyrodrift::ErrorKind::kUsage);
  } catch (const gyrodrift::OptionError& e) {
    fmt::print(stderr, "gyrodrift: error: {}\n", gyrodrift::cli::OptionErrorMessage(e));
    return gyrodrift::ExitCode(e.kind());
  } catch (const gyrodrift::Error& e) {
    fmt::print(stderr, "gyrodrift: error: {}\n", e.what());
    return gyrodrift::ExitCode(e.kind());
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "gyrodrift: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "gyrodrift: internal error: {}\n", e.what());
    return 1;
  }
  return 0;
}
