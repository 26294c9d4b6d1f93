// The files of per-vertex maps over a base given on the command line (issue 25): a mask
// (`surface --mask`, core/surface/surface_mask) and a size map (`surface --size-map`,
// SurfaceQuiltingOptions::size_map). Text, one value per line; fuzzed (fuzz/).
#pragma once

#include <string>

#include "core/mesh/mesh.h"
#include "core/surface/surface_mask.h"

namespace mq {

// Parses a mask for `base` (the base as given) from `text`, named `name` in messages. Lines
// empty or starting with '#' are skipped. Either one number per base vertex, in [0, 1]; or a
// first line `faces` and then one 0-based face index per line. Throws InvalidInput (one line:
// name, line number) for a wrong count, a value that is not a number in [0, 1], an index out of
// range, or a mask that sets nothing.
SurfaceMask parse_surface_mask(const std::string& text, const std::string& name,
                               const TriMesh& base);

// parse_surface_mask on a file's contents (a regular file, core/mesh/input_file).
SurfaceMask read_surface_mask(const std::string& path, const TriMesh& base);

// A size map (SurfaceQuiltingOptions::size_map, `surface --size-map`) for `base` from `text`:
// one element size factor per base vertex (> 0, finite; 1 is the size --scale or
// --element-size sets), lines empty or starting with '#' skipped. Throws InvalidInput (one
// line: name, line number) for a value that is not such a number or a wrong count. The range
// is checked where the options are validated.
Eigen::VectorXd parse_size_map(const std::string& text, const std::string& name,
                               const TriMesh& base);

// parse_size_map on a file's contents (a regular file, core/mesh/input_file).
Eigen::VectorXd read_size_map(const std::string& path, const TriMesh& base);

}  // namespace mq
