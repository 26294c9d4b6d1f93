// The output of local-patch synthesis (paper section 3.1) as it grows: elements in local
// coordinates over the refined base, and the same store seen through one patch frame, where the
// planar steps of section 2 (core/planar/patch_quilting) add, replace and remove elements.
#pragma once

#include <map>
#include <set>
#include <vector>

#include "core/planar/patch_quilting.h"
#include "core/surface/surface_quilting.h"

namespace mq {

// The output elements in local coordinates, with an index from base faces to the elements that
// have vertices above them.
struct SurfaceStore {
  std::vector<SurfaceElement> elements;
  std::vector<unsigned char> alive;       // per element: not removed
  std::vector<std::vector<int>> by_face;  // per base face: elements over it, ascending

  explicit SurfaceStore(int num_faces) : by_face(static_cast<size_t>(num_faces)) {}
  // Indexes element `id` under the base faces its vertices lie on (call after setting it).
  void index(int id);
  // Appends an element, alive and indexed; returns its id.
  int add(SurfaceElement e);
};

// The store seen through one patch frame: the elements near the patch, flattened (`frame`, by
// id). Elements added or replaced here are listed by changed(); the caller writes them back to
// the store in local coordinates.
class FramedOutput final : public PatchOutput {
 public:
  FramedOutput(SurfaceStore& store, std::map<int, Element> frame)
      : store_(store), frame_(std::move(frame)) {}

  const Element& element(int id) const override { return frame_.at(id); }
  bool alive(int id) const override { return store_.alive[id] != 0 && frame_.count(id); }
  std::vector<int> elements_near(const Vector2d& lo, const Vector2d& hi) const override;
  int add(Element e) override;
  void replace(int id, Element e) override {
    frame_[id] = std::move(e);
    changed_.insert(id);
  }
  void remove(int id) override { store_.alive[id] = 0; }

  const std::set<int>& changed() const { return changed_; }
  const Element& frame_element(int id) const { return frame_.at(id); }

 private:
  SurfaceStore& store_;
  std::map<int, Element> frame_;
  std::set<int> changed_;
};

}  // namespace mq
