// The `sft` command line: one table of commands, one file per command (apps/<name>_command.cc).
#include <glog/logging.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "apps/commands.h"

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = google::GLOG_WARNING;
  return sft::RunCommandTable(argc, argv);
}
