#include <exception>
#include <iostream>

#include "cli.h"

int main(int argc, char** argv) {
  try {
    return optique::node::run_cli(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "optique-node: fatal: " << e.what() << "\n";
    return 1;
  }
}
