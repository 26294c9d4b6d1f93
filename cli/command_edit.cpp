// meshquilt edit: a saved quilt edited element by element (issue 25): remove elements, or give
// them a material, a colour or a palette of looks, chosen by id, kind or region.
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/run_context.h"
#include "core/common/errors.h"
#include "core/shell/element_editing.h"
#include "core/shell/saved_quilt.h"

namespace mq::cli {

namespace {

// "3,7,10-20" -> 3, 7, 10, ..., 20. Throws UsageError for anything else.
std::vector<int> parse_ids(const std::string& text) {
  std::vector<int> ids;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    int a = 0, b = 0, used = 0;
    if (parse_range(item, a, b) && b - a < 10'000'000) {
      for (int i = a; i <= b; ++i) ids.push_back(i);
    } else if (std::sscanf(item.c_str(), "%d%n", &a, &used) == 1 &&
               used == static_cast<int>(item.size()) && a >= 0) {
      ids.push_back(a);
    } else {
      throw UsageError("--ids expects ids and ranges such as 3,7,10-20, got '" + text + "'");
    }
  }
  if (ids.empty()) throw UsageError("--ids expects ids and ranges such as 3,7,10-20");
  return ids;
}

}  // namespace

int run_edit(int argc, char** argv, int first) {
  CommandLine cl(
      "edit", "--quilt FILE -o FILE (--remove | --material NAME | --color RRGGBB | --palette N)",
      "Edits a quilt saved by 'meshquilt surface --save-quilt' element by element, without a new\n"
      "synthesis; 'meshquilt embed' then writes it on any pose of its base. The elements are\n"
      "those meeting every one of --ids, --kind, --sphere and --box given (none: all), ids as\n"
      "every output numbers them (element_id, the OBJ's objects), regions tested at each\n"
      "element's centre in the pose it was made in. Then exactly one action:\n"
      "  --remove            remove them\n"
      "  --material NAME     give them the kind NAME (a material of its own in every file)\n"
      "  --color RRGGBB      give them that colour (sRGB, hexadecimal: kind color_RRGGBB)\n"
      "  --palette N         give each one of N looks of its kind at random (kinds KIND_1..N)");
  cl.option("quilt", "FILE", "a quilt saved by 'surface --save-quilt'");
  cl.option("output", "FILE", "the edited quilt");
  cl.option("ids", "LIST", "elements by id: 3,7,10-20");
  cl.option("kind", "NAME", "elements of this kind");
  cl.option("sphere", "X Y Z R", "elements whose centre lies in this sphere", "", 4);
  cl.option("box", "X0 Y0 Z0 X1 Y1 Z1", "elements whose centre lies in this box", "", 6);
  cl.flag("remove", "remove the elements");
  cl.option("material", "NAME", "give the elements this kind");
  cl.option("color", "RRGGBB", "give the elements this colour");
  cl.option("palette", "N", "give each element one of N looks of its kind at random");
  cl.option("seed", "N", "random seed of --palette", "1");
  cl.flag("quiet", "print nothing on success");
  if (!cl.parse(argc, argv, first)) return 0;
  if (!cl.has("quilt")) throw UsageError("--quilt FILE is required");
  if (!cl.has("output")) throw UsageError("-o FILE is required");
  if (cl.has("remove") + cl.has("material") + cl.has("color") + cl.has("palette") != 1)
    throw UsageError("give exactly one of --remove, --material, --color and --palette");
  ElementSelection selection;
  if (cl.has("ids")) selection.ids = parse_ids(cl.get("ids"));
  selection.kind = cl.get("kind");
  if (cl.has("sphere")) {
    selection.sphere = true;
    selection.centre = Vector3d(cl.get_double("sphere", 0), cl.get_double("sphere", 1),
                                cl.get_double("sphere", 2));
    selection.radius = cl.get_double("sphere", 3, 0.0, 1e300);
  }
  if (cl.has("box")) {
    selection.box = true;
    for (int k = 0; k < 3; ++k) {
      selection.lo(k) = cl.get_double("box", k);
      selection.hi(k) = cl.get_double("box", 3 + k);
    }
    if (!(selection.lo.array() <= selection.hi.array()).all())
      throw UsageError("--box expects the lower corner first");
  }
  std::string color;
  if (cl.has("color")) {
    color = cl.get("color");
    if (color.size() != 6 || color.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
      throw UsageError("--color expects six hexadecimal digits RRGGBB, got '" + color + "'");
  }
  const int palette = cl.has("palette") ? static_cast<int>(cl.get_int("palette", 1, 256)) : 0;
  const auto seed = static_cast<std::uint64_t>(cl.get_int("seed", 0, (1LL << 62)));
  check_paths({cl.get("output")}, {cl.get("quilt")});

  SavedQuilt quilt = read_saved_quilt(cl.get("quilt"));
  const std::vector<char> chosen = select_elements(quilt, selection);
  const auto count = static_cast<int>(std::count(chosen.begin(), chosen.end(), 1));
  if (cl.has("remove")) {
    MQ_CHECK(count < static_cast<int>(chosen.size()), InvalidInput, "that would remove all ",
             chosen.size(), " elements; nothing written");
    remove_elements(quilt, chosen);
  } else if (cl.has("material")) {
    set_element_kind(quilt, chosen, cl.get("material"));
  } else if (cl.has("color")) {
    set_element_kind(quilt, chosen, "color_" + color);
  } else {
    assign_palette(quilt, chosen, palette, seed);
  }
  write_saved_quilt(cl.get("output"), quilt);
  if (!cl.has("quiet"))
    std::printf("wrote %s: %d of %zu elements %s\n", cl.get("output").c_str(), count, chosen.size(),
                cl.has("remove")    ? "removed"
                : cl.has("palette") ? "given a palette"
                                    : "given the kind");
  return 0;
}

}  // namespace mq::cli
