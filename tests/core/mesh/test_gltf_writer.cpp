// The .glb writer checked against the Khronos glTF 2.0 rules it must follow: the binary header
// and chunks (magic, version, lengths, 4-byte padding, chunk types), every accessor inside its
// buffer view and the view inside the buffer, the component types and counts each attribute
// semantic allows, POSITION min/max equal to the data, indices inside the vertex range; then
// read back by tinygltf as an independent reader.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include "core/common/errors.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/gltf_writer.h"
#include "core/mesh/mesh_topology.h"
#include "core/planar/swatch_generators.h"
#include "tests/test_support.h"

namespace mq {
namespace {

uint32_t u32(const std::string& b, size_t at) {
  uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;  // the test machines are little-endian, as glTF is
}

int component_size(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
  }
  return 0;
}

// Checks a .glb; `model` receives what tinygltf reads.
void check_glb_into(const std::string& path, tinygltf::Model& model) {
  const std::string b = test::slurp(path);
  EXPECT_GE(b.size(), 28u);
  EXPECT_EQ(b.substr(0, 4), "glTF");
  EXPECT_EQ(u32(b, 4), 2u);
  EXPECT_EQ(u32(b, 8), b.size());  // header length is the file's
  const uint32_t json_length = u32(b, 12);
  EXPECT_EQ(u32(b, 16), 0x4E4F534Au);  // "JSON"
  EXPECT_EQ(json_length % 4, 0u);
  EXPECT_LE(20 + json_length + 8, b.size());
  const size_t bin_at = 20 + json_length;
  const uint32_t bin_length = u32(b, bin_at);
  EXPECT_EQ(u32(b, bin_at + 4), 0x004E4942u);  // "BIN"
  EXPECT_EQ(bin_length % 4, 0u);
  EXPECT_EQ(bin_at + 8 + bin_length, b.size());
  // JSON padding is spaces.
  const std::string json = b.substr(20, json_length);
  const size_t last = json.find_last_not_of(' ');
  EXPECT_EQ(json[last], '}');

  tinygltf::TinyGLTF loader;
  std::string err, warn;
  EXPECT_TRUE(loader.LoadBinaryFromMemory(&model, &err, &warn,
                                          reinterpret_cast<const unsigned char*>(b.data()),
                                          static_cast<unsigned>(b.size())))
      << err;
  EXPECT_EQ(model.asset.version, "2.0");
  EXPECT_EQ(model.buffers.size(), 1u);
  EXPECT_LE(model.buffers[0].data.size(), bin_length);
  for (const auto& v : model.bufferViews) {
    EXPECT_EQ(v.buffer, 0);
    EXPECT_LE(v.byteOffset + v.byteLength, model.buffers[0].data.size());
    EXPECT_EQ(v.byteOffset % 4, 0u);
  }
  for (const auto& a : model.accessors) {
    ASSERT_GE(a.bufferView, 0);
    const auto& v = model.bufferViews[static_cast<size_t>(a.bufferView)];
    const size_t elem = static_cast<size_t>(component_size(a.componentType)) *
                        static_cast<size_t>(tinygltf::GetNumComponentsInType(a.type));
    ASSERT_GT(elem, 0u);
    EXPECT_EQ(a.byteOffset % static_cast<size_t>(component_size(a.componentType)), 0u);
    EXPECT_LE(a.byteOffset + a.count * elem, v.byteLength);
    EXPECT_GT(a.count, 0u);
  }
  for (const auto& mesh : model.meshes)
    for (const auto& p : mesh.primitives) {
      EXPECT_EQ(p.mode, TINYGLTF_MODE_TRIANGLES);
      ASSERT_TRUE(p.attributes.count("POSITION"));
      const auto& pos = model.accessors[static_cast<size_t>(p.attributes.at("POSITION"))];
      for (const auto& [semantic, index] : p.attributes) {
        const auto& a = model.accessors[static_cast<size_t>(index)];
        EXPECT_EQ(a.count, pos.count) << semantic;  // one value per vertex
        if (semantic == "POSITION" || semantic == "NORMAL") {
          EXPECT_EQ(a.type, TINYGLTF_TYPE_VEC3);
          EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
        } else {
          EXPECT_EQ(semantic[0], '_') << "application attributes start with an underscore";
          EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
        }
      }
      // POSITION min/max are required and must be the data's bounds.
      ASSERT_EQ(pos.minValues.size(), 3u);
      ASSERT_EQ(pos.maxValues.size(), 3u);
      const auto& view = model.bufferViews[static_cast<size_t>(pos.bufferView)];
      const float* P = reinterpret_cast<const float*>(model.buffers[0].data.data() +
                                                      view.byteOffset + pos.byteOffset);
      for (int k = 0; k < 3; ++k) {
        float lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < pos.count; ++i) {
          lo = std::min(lo, P[3 * i + k]);
          hi = std::max(hi, P[3 * i + k]);
        }
        EXPECT_EQ(pos.minValues[static_cast<size_t>(k)], lo);
        EXPECT_EQ(pos.maxValues[static_cast<size_t>(k)], hi);
      }
      const auto& ia = model.accessors[static_cast<size_t>(p.indices)];
      EXPECT_EQ(ia.type, TINYGLTF_TYPE_SCALAR);
      EXPECT_EQ(ia.count % 3, 0u);
      const auto& iv = model.bufferViews[static_cast<size_t>(ia.bufferView)];
      EXPECT_EQ(iv.target, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
      const uint32_t* I = reinterpret_cast<const uint32_t*>(model.buffers[0].data.data() +
                                                            iv.byteOffset + ia.byteOffset);
      for (size_t i = 0; i < ia.count; ++i) ASSERT_LT(I[i], pos.count);
      EXPECT_GE(p.material, 0);
    }
}

tinygltf::Model check_glb(const std::string& path) {
  tinygltf::Model model;
  check_glb_into(path, model);
  return model;
}

template <typename T>
const T* accessor_data(const tinygltf::Model& m, int accessor) {
  const auto& a = m.accessors[static_cast<size_t>(accessor)];
  const auto& v = m.bufferViews[static_cast<size_t>(a.bufferView)];
  return reinterpret_cast<const T*>(m.buffers[0].data.data() + v.byteOffset + a.byteOffset);
}

TEST(GltfWriter, IvyIsValidWithAMaterialPerKindAndElementIds) {
  IvyOptions o;
  o.leaves = 6;
  const TriMesh ivy = ivy_section(o);
  const std::string path = test::temp_dir() + "/ivy.glb";
  write_glb(path, ivy);
  const tinygltf::Model m = check_glb(path);
  ASSERT_EQ(m.meshes.size(), 1u);
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].name, "vine");
  EXPECT_EQ(m.materials[1].name, "leaf");
  // Faces: all of them, each primitive's triangles of one kind.
  size_t triangles = 0;
  std::vector<int> fc;
  const int elements = connected_components(ivy.F, ivy.num_vertices(), fc);
  std::set<int> ids_seen;
  for (const auto& p : m.meshes[0].primitives) {
    const auto& ia = m.accessors[static_cast<size_t>(p.indices)];
    triangles += ia.count / 3;
    const uint32_t* I = accessor_data<uint32_t>(m, p.indices);
    const float* id = accessor_data<float>(m, p.attributes.at("_ELEMENT_ID"));
    for (size_t t = 0; t < ia.count / 3; ++t) {
      // The three corners of a triangle belong to one element, and ids are whole numbers.
      const float e = id[I[3 * t]];
      EXPECT_EQ(e, id[I[3 * t + 1]]);
      EXPECT_EQ(e, id[I[3 * t + 2]]);
      EXPECT_EQ(e, std::floor(e));
      ids_seen.insert(static_cast<int>(e));
      // Element 0 is the vine (first in the file), the rest are leaves.
      EXPECT_EQ(e == 0, m.materials[static_cast<size_t>(p.material)].name == "vine");
    }
  }
  EXPECT_EQ(triangles, static_cast<size_t>(ivy.num_faces()));
  EXPECT_EQ(static_cast<int>(ids_seen.size()), elements);
  // Normals are unit.
  const auto& p0 = m.meshes[0].primitives[0];
  const float* N = accessor_data<float>(m, p0.attributes.at("NORMAL"));
  for (size_t i = 0; i < m.accessors[static_cast<size_t>(p0.attributes.at("NORMAL"))].count; ++i)
    ASSERT_NEAR(
        std::sqrt(N[3 * i] * N[3 * i] + N[3 * i + 1] * N[3 * i + 1] + N[3 * i + 2] * N[3 * i + 2]),
        1.0, 1e-5);
}

// Two kinds named alike once sanitised ("a b", "a_b") are two materials of different names
// (issue 28).
TEST(GltfWriter, KindsNamedAlikeAreDistinctMaterials) {
  IvyOptions o;
  o.leaves = 2;
  TriMesh ivy = ivy_section(o);
  ivy.kinds = {"a b", "a_b"};
  const std::string path = test::temp_dir() + "/alike.glb";
  write_glb(path, ivy);
  const tinygltf::Model m = check_glb(path);
  ASSERT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[0].name, "a_b");
  EXPECT_EQ(m.materials[1].name, "a_b_2");
}

TEST(GltfWriter, MeshWithoutKindsAndSameBytesEveryTime) {
  const TriMesh t = test::torus(1.0, 0.25, 32, 12);
  const std::string dir = test::temp_dir();
  write_glb(dir + "/a.glb", t);
  const std::string first = test::slurp(dir + "/a.glb");
  write_glb(dir + "/a.glb", t);
  EXPECT_TRUE(test::slurp(dir + "/a.glb") == first);  // (the mesh is named after the file)
  const tinygltf::Model m = check_glb(dir + "/a.glb");
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, kDefaultKind);
  // A smooth torus has no crease: one glTF vertex per mesh vertex.
  EXPECT_EQ(m.accessors[0].count, static_cast<size_t>(t.num_vertices()));
}

TEST(GltfWriter, ThroughWriteMeshAndReadingIsRefusedByName) {
  const std::string dir = test::temp_dir();
  WeaveOptions w;
  w.threads_x = 2;
  w.threads_y = 2;
  write_mesh(dir + "/w.glb", plain_weave(w));
  const tinygltf::Model m = check_glb(dir + "/w.glb");
  EXPECT_EQ(m.materials.size(), 2u);
  // The flat end caps are creases: more glTF vertices than mesh vertices.
  EXPECT_GT(m.accessors[0].count, static_cast<size_t>(plain_weave(w).num_vertices()));
  try {
    read_mesh(dir + "/w.glb");
    FAIL() << "read a .glb";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("output format"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mq
