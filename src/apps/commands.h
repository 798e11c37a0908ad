// src/apps/commands.h — the subcommands of the `phnn` executable.
#pragma once

namespace phnn {
namespace apps {

/// Each returns the process exit status; argv[first] is the first argument
/// after the subcommand name.
int run_data(int argc, char** argv, int first);
int run_import(int argc, char** argv, int first);
int run_train(int argc, char** argv, int first);
int run_sweep(int argc, char** argv, int first);
int run_reduce(int argc, char** argv, int first);
int run_merge(int argc, char** argv, int first);
int run_eval(int argc, char** argv, int first);
int run_verify(int argc, char** argv, int first);

}  // namespace apps
}  // namespace phnn
