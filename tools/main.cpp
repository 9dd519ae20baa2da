#include <exception>
#include <iostream>

#include "tools/cli.h"

int main(int argc, char** argv) {
  try {
    return optique::tools::run_cli(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "optique-tools: fatal: " << e.what() << "\n";
    return 1;
  }
}
