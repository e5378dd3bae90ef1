// misalloc devices: the OpenCL platforms and devices that --device chooses from.
#include <iostream>

#include "cl/Device.h"
#include "cli/Subcommand.h"

namespace misalloc {

Subcommand addDevicesCommand(CLI::App& app) {
  return {app.add_subcommand("devices", "list OpenCL platforms and devices"), [] {
            listDevices(std::cout);
            return 0;
          }};
}

}  // namespace misalloc
