#include <exception>
#include <iostream>

#include "master/app/cli.h"

int main(int argc, char** argv) {
  try {
    return optique::master::run_cli(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "optique-master: fatal: " << e.what() << "\n";
    return 1;
  }
}
