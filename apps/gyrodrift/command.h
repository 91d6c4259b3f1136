// Subcommand registry: each *_command.cc registers itself with a static Command object, so adding
// a subcommand touches no other file. The order value fixes the order in --help.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace gyrodrift::cli {

struct Command {
  std::string name;
  int order;
  // Adds the subcommand to `app` and wires its callback; the callback may throw gyrodrift::Error.
  std::function<void(CLI::App& app)> setup;
};

std::vector<Command>& Commands();

struct RegisterCommand {
  RegisterCommand(std::string name, int order, std::function<void(CLI::App&)> setup) {
    Commands().push_back({std::move(name), order, std::move(setup)});
  }
};

}  // namespace gyrodrift::cli
