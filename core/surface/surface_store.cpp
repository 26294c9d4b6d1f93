#include "core/surface/surface_store.h"

#include <algorithm>
#include <utility>

namespace mq {

void SurfaceStore::index(int id) {
  std::vector<int> faces = elements[id].face;
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  for (const int f : faces)
    if (by_face[f].empty() || by_face[f].back() != id) by_face[f].push_back(id);
}

int SurfaceStore::add(SurfaceElement e) {
  elements.push_back(std::move(e));
  alive.push_back(1);
  index(static_cast<int>(elements.size()) - 1);
  return static_cast<int>(elements.size()) - 1;
}

std::vector<int> FramedOutput::elements_near(const Vector2d& lo, const Vector2d& hi) const {
  std::vector<int> ids;
  for (const auto& [id, e] : frame_)
    if (store_.alive[id] && e.lo.x() <= hi.x() && e.hi.x() >= lo.x() && e.lo.y() <= hi.y() &&
        e.hi.y() >= lo.y())
      ids.push_back(id);
  return ids;
}

int FramedOutput::add(Element e) {
  const int id = static_cast<int>(store_.elements.size());
  store_.elements.emplace_back();  // filled in local coordinates by the caller
  store_.alive.push_back(1);
  frame_[id] = std::move(e);
  changed_.insert(id);
  return id;
}

}  // namespace mq
