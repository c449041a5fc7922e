// Stand-alone entry point for the `gtsp` subcommand: `covplan-gtsp FILE ...`.
#include <string>
#include <vector>

#include "client/gtsp_command.h"

int main(int argc, char** argv) {
  return covplan::RunGtspCommand(std::vector<std::string>(argv + 1, argv + argc));
}
