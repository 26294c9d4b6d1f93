// Writing files so that a failed run never leaves a partial output: the bytes go to a temporary
// file in the destination directory, which is renamed over the destination only when complete.
#pragma once

#include <string>
#include <string_view>

namespace mq {

// Writes `bytes` to `path` atomically. Throws Error naming the file on any I/O failure, in
// which case `path` is unchanged and no temporary file remains.
void write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace mq
