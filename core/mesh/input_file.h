// Reading a whole input file (a mesh, key vectors, a field) with the checks every reader needs
// before it trusts the bytes: a regular file (a FIFO would block forever, /dev/zero or
// /dev/urandom never end), and a bounded size.
#pragma once

#include <cstddef>
#include <string>

namespace mq {

// Default bound of read_input_file: 4 GiB, more than the largest mesh the tool can process in
// the memory of the machines it is built for.
inline constexpr std::size_t kMaxInputBytes = std::size_t{4} << 30;

// The bytes of the file at path. `what` names the file's role in messages ("mesh file").
// Throws InvalidInput "PATH: cannot read WHAT: REASON" for a missing or unreadable file, a
// directory, a file that is not a regular file (FIFO, socket, device), or one larger than
// max_bytes.
std::string read_input_file(const std::string& path, const char* what,
                            std::size_t max_bytes = kMaxInputBytes);

}  // namespace mq
