// The subcommands of the meshquilt executable. Each parses argv[first..argc) itself and returns
// the process exit status; errors propagate as mq::Error / cli::UsageError to main().
#pragma once

namespace mq::cli {

int run_info(int argc, char** argv, int first);
int run_swatch(int argc, char** argv, int first);
int run_render(int argc, char** argv, int first);
int run_plane(int argc, char** argv, int first);
int run_surface(int argc, char** argv, int first);
int run_embed(int argc, char** argv, int first);
int run_edit(int argc, char** argv, int first);

}  // namespace mq::cli
