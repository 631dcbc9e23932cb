// gmsh MSH 4.1 reader, ASCII and binary: the meshes of data/make_layered_tube.py (a two-layer
// tube piece of tet10/tri6) and corrupted copies of them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <set>
#include <string>

#include <unistd.h>

#include "angio/solid/elements.hpp"
#include "angio/solid/mesh.hpp"

using namespace angio::solid;

namespace {

const std::string kData = ANGIO_SOLID_TEST_DATA;
const std::string kAscii = kData + "/layered_tube_ascii.msh";
const std::string kBinary = kData + "/layered_tube_binary.msh";

Mesh read_tube(const std::string& path) { return read_gmsh(path, "artery", "artery_"); }

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// A scratch file per test (the test cases may run in parallel processes).
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& tag) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = (std::filesystem::temp_directory_path() /
             (std::string("angio_gmsh_") + info->test_suite_name() + "_" + info->name() + "_" + tag + "_" +
              std::to_string(::getpid()) + ".msh"))
                .string();
  }
  ~ScratchFile() { std::filesystem::remove(path_); }
  const std::string& write(const std::string& bytes) {
    std::ofstream(path_, std::ios::binary | std::ios::trunc) << bytes;
    return path_;
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// The message of the runtime_error read_gmsh throws; fails the test if it returns or throws
// anything else (bad_alloc, out_of_range, ...).
std::string read_error(const std::string& path) {
  try {
    read_tube(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << path << " was read without an error";
  return "";
}

template <class T>
void patch(std::string& bytes, size_t offset, T value) {
  ASSERT_LE(offset + sizeof(T), bytes.size());
  std::memcpy(bytes.data() + offset, &value, sizeof(T));
}

// Byte offset just after the line "$<section>\n" of a (binary) msh file.
size_t section_data(const std::string& bytes, const std::string& section) {
  const size_t at = bytes.find("\n" + section + "\n");
  EXPECT_NE(at, std::string::npos) << section;
  return at + section.size() + 2;
}

Eigen::MatrixXd coordinates(const Mesh& m, const Element& e) {
  Eigen::MatrixXd X(e.nn(), 3);
  for (int a = 0; a < e.nn(); ++a) X.row(a) = m.X[e.n[a]].transpose();
  return X;
}

}  // namespace

TEST(GmshReader, AsciiAndBinaryGiveTheSameMesh) {
  const Mesh a = read_tube(kAscii);
  const Mesh b = read_tube(kBinary);
  ASSERT_GT(a.elements.size(), 100u);
  ASSERT_EQ(a.X.size(), b.X.size());
  for (size_t i = 0; i < a.X.size(); ++i)  // ASCII has 16 significant digits
    EXPECT_LT((a.X[i] - b.X[i]).norm(), 1e-14) << "node " << i;
  ASSERT_EQ(a.elements.size(), b.elements.size());
  for (size_t e = 0; e < a.elements.size(); ++e) {
    EXPECT_EQ(a.elements[e].type, ElemType::Tet10);
    EXPECT_EQ(a.elements[e].block, b.elements[e].block);
    EXPECT_EQ(a.elements[e].n, b.elements[e].n) << "element " << e;
  }
  ASSERT_EQ(a.blocks.size(), 2u);
  EXPECT_EQ(a.blocks[0].name, "media");
  EXPECT_EQ(a.blocks[1].name, "adventitia");
  EXPECT_EQ(a.blocks[0].part, "artery");
  for (size_t k = 0; k < a.blocks.size(); ++k) EXPECT_EQ(a.blocks[k].name, b.blocks[k].name);
  for (const char* name : {"artery_inner", "artery_outer", "artery_end0", "artery_end1"}) {
    const SurfaceSet* sa = a.surface(name);
    const SurfaceSet* sb = b.surface(name);
    ASSERT_NE(sa, nullptr) << name;
    ASSERT_NE(sb, nullptr) << name;
    ASSERT_GT(sa->faces.size(), 0u) << name;
    ASSERT_EQ(sa->faces.size(), sb->faces.size()) << name;
    for (size_t f = 0; f < sa->faces.size(); ++f) {
      EXPECT_EQ(sa->faces[f].type, FaceType::Tri6);
      EXPECT_EQ(sa->faces[f].n, sb->faces[f].n) << name << " face " << f;
    }
  }
  EXPECT_EQ(a.surfaces.size(), 4u);  // the sector's cut planes have no physical group
}

// Both layers are there, in their radial range (blocks after the physical groups, not entities).
TEST(GmshReader, BlocksFollowTheLayers) {
  const Mesh m = read_tube(kBinary);
  std::set<int> seen;
  for (size_t e = 0; e < m.elements.size(); ++e) {
    const Vec3d c = element_centroid(m, int(e));
    const double r = std::hypot(c.x(), c.y());
    const std::string& layer = m.blocks[m.elements[e].block].name;
    seen.insert(m.elements[e].block);
    if (layer == "media") {
      EXPECT_GT(r, 1.5 - 1e-9);
      EXPECT_LT(r, 1.7);
    } else {
      EXPECT_GT(r, 1.7);
      EXPECT_LT(r, 2.0 + 1e-9);
    }
  }
  EXPECT_EQ(seen.size(), 2u);
}

TEST(GmshReader, Tet10ReferenceJacobianPositive) {
  const Mesh m = read_tube(kBinary);
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  for (size_t e = 0; e < m.elements.size(); ++e) {
    const Element& el = m.elements[e];
    ASSERT_EQ(el.type, ElemType::Tet10);
    const Eigen::MatrixXd X = coordinates(m, el);
    for (const auto& q : volume_rule(el.type)) {
      shape(el.type, q.xi, N, dN);
      const Eigen::Matrix3d J = X.transpose() * dN;  // dX/dxi
      EXPECT_GT(J.determinant(), 0.0) << "element " << e;
    }
  }
}

// Oriented faces point out of the wall: inner toward the axis, outer away, end0 -z, end1 +z.
TEST(GmshReader, SurfacesOrientedOutward) {
  Mesh m = read_tube(kAscii);
  ASSERT_NO_THROW(m.orient_surfaces());
  auto check = [&](const char* name, auto outward) {
    for (const Face& f : m.surface(name)->faces) {
      Eigen::MatrixXd X(f.nn(), 3);
      Vec3d c = Vec3d::Zero();
      for (int a = 0; a < f.nn(); ++a) {
        X.row(a) = m.X[f.n[a]].transpose();
        c += m.X[f.n[a]] / f.nn();
      }
      EXPECT_GT(face_area_vector(f.type, X).dot(outward(c)), 0.0) << name;
    }
  };
  check("artery_inner", [](const Vec3d& c) { return Vec3d(-c.x(), -c.y(), 0); });
  check("artery_outer", [](const Vec3d& c) { return Vec3d(c.x(), c.y(), 0); });
  check("artery_end0", [](const Vec3d&) { return Vec3d(0, 0, -1); });
  check("artery_end1", [](const Vec3d&) { return Vec3d(0, 0, 1); });
}

TEST(GmshReader, ScaleMultipliesCoordinates) {
  const Mesh a = read_tube(kBinary);
  const Mesh b = read_gmsh(kBinary, "artery", "artery_", 1e-3);
  ASSERT_EQ(a.X.size(), b.X.size());
  for (size_t i = 0; i < a.X.size(); i += 17) EXPECT_NEAR((1e-3 * a.X[i] - b.X[i]).norm(), 0.0, 1e-18);
}

// Every truncation of the binary file is an error naming the file (never a crash or bad_alloc).
TEST(GmshReader, TruncatedBinaryFileRefused) {
  const std::string bytes = slurp(kBinary);
  ScratchFile tmp("truncated");
  for (size_t n = 0; n + 1 < bytes.size(); n += 211) {
    const std::string msg = read_error(tmp.write(bytes.substr(0, n)));
    EXPECT_NE(msg.find(tmp.path()), std::string::npos) << "length " << n << ": " << msg;
  }
  // cut in the middle of the node coordinates: the message says where
  const std::string msg = read_error(tmp.write(bytes.substr(0, section_data(bytes, "$Nodes") + 200)));
  EXPECT_NE(msg.find("byte offset"), std::string::npos) << msg;
}

// Huge counts are refused before anything is allocated, with the file and the byte offset.
TEST(GmshReader, HugeCountRefused) {
  const std::string bytes = slurp(kBinary);
  ScratchFile tmp("huge");
  const uint64_t huge = uint64_t(1) << 62;
  const size_t nodes = section_data(bytes, "$Nodes");
  const size_t elements = section_data(bytes, "$Elements");
  const size_t entities = section_data(bytes, "$Entities");
  struct Case {
    size_t offset;
    const char* field;
  };
  // $Nodes/$Elements: 4 size_t header, then the first block: 3 ints and its size_t count.
  // $Entities: 4 size_t counts, the first point: int tag, 3 doubles, size_t numPhysicalTags.
  for (const Case& c : {Case{nodes, "numEntityBlocks"}, Case{nodes + 32 + 12, "numNodesInBlock"},
                        Case{elements, "numEntityBlocks"}, Case{elements + 32 + 12, "numElementsInBlock"},
                        Case{entities, "number of entities"}, Case{entities + 32 + 4 + 24, "numPhysicalTags"}}) {
    std::string b = bytes;
    patch(b, c.offset, huge);
    const std::string msg = read_error(tmp.write(b));
    EXPECT_NE(msg.find(tmp.path()), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.field), std::string::npos) << msg;
    EXPECT_NE(msg.find("byte offset " + std::to_string(c.offset)), std::string::npos) << msg;
  }
  // the same in an ASCII file: the node count of the first block (line 2 of $Nodes)
  std::string a = slurp(kAscii);
  const size_t block = a.find('\n', section_data(a, "$Nodes")) + 1;
  const size_t count = a.find('\n', block);
  a.replace(block, count - block, "0 1 0 999999999999");
  const std::string msg = read_error(tmp.write(a));
  EXPECT_NE(msg.find(tmp.path() + ":"), std::string::npos) << msg;
  EXPECT_NE(msg.find("numNodesInBlock"), std::string::npos) << msg;
}

// Random single-byte corruption: read_gmsh either succeeds or throws runtime_error.
TEST(GmshReader, CorruptedBytesGiveRuntimeErrors) {
  const std::string bytes = slurp(kBinary);
  ScratchFile tmp("corrupt");
  std::mt19937 rng(12345);
  std::uniform_int_distribution<size_t> where(0, bytes.size() - 1);
  std::uniform_int_distribution<int> what(0, 255);
  // Any other exception (bad_alloc, length_error) or a crash fails the test; a changed coordinate or
  // tag may still be a valid mesh, but a good share of the changes hit counts and sizes.
  int refused = 0;
  for (int i = 0; i < 300; ++i) {
    std::string b = bytes;
    b[where(rng)] = char(what(rng));
    try {
      read_tube(tmp.write(b));
    } catch (const std::runtime_error& e) {
      ++refused;
      EXPECT_NE(std::string(e.what()).find(tmp.path()), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(refused, 0);
}

TEST(GmshReader, OtherVersionsAndByteOrderRefused) {
  std::string msg = read_error(kData + "/cube_v22.msh");
  EXPECT_NE(msg.find("cube_v22.msh"), std::string::npos) << msg;
  EXPECT_NE(msg.find("MSH 2.2 ASCII"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected MSH 4.1"), std::string::npos) << msg;

  ScratchFile tmp("version");
  std::string b = slurp(kBinary);
  ASSERT_EQ(b.compare(0, 20, "$MeshFormat\n4.1 1 8\n"), 0);
  b.replace(12, 3, "4.0");
  msg = read_error(tmp.write(b));
  EXPECT_NE(msg.find("MSH 4.0 binary"), std::string::npos) << msg;
  b.replace(12, 3, "2.2");
  msg = read_error(tmp.write(b));
  EXPECT_NE(msg.find("MSH 2.2 binary"), std::string::npos) << msg;

  b = slurp(kBinary);
  patch(b, 20, int32_t(0x01000000));  // the int 1 as a big-endian machine writes it
  msg = read_error(tmp.write(b));
  EXPECT_NE(msg.find("byte order"), std::string::npos) << msg;
  EXPECT_NE(msg.find(tmp.path()), std::string::npos) << msg;
}

// Unknown sections are skipped in both encodings; a partitioned mesh is refused.
TEST(GmshReader, UnknownSectionsSkippedPartitionedRefused) {
  ScratchFile tmp("sections");
  for (const std::string& path : {kAscii, kBinary}) {
    std::string b = slurp(path);
    const size_t nodes = b.find("$Nodes\n");
    b.insert(nodes, std::string("$Periodic\n1\n") + std::string("\0\x01$Endx\n\xff", 9) + "\n$EndPeriodic\n");
    const Mesh m = read_tube(tmp.write(b));
    EXPECT_EQ(m.elements.size(), read_tube(path).elements.size());
    b.insert(nodes, "$PartitionedEntities\n2\n0\n$EndPartitionedEntities\n");
    const std::string msg = read_error(tmp.write(b));
    EXPECT_NE(msg.find("partitioned"), std::string::npos) << msg;
  }
}

// Reference validity (exact geometry): the tube is valid; one element turned inside out by swapping
// two corner nodes (a mirror image: det J changes sign everywhere) is found at a Gauss point; a tet10
// whose mid-edge node is pulled past the corner at the end of its edge folds there and is found.
TEST(MeshValidity, InvertedAndFoldedElementsFound) {
  Mesh m = read_tube(kBinary);
  EXPECT_EQ(first_invalid_element(m), "");
  Mesh swapped = m;
  std::swap(swapped.elements[7].n[0], swapped.elements[7].n[1]);
  const std::string what = first_invalid_element(swapped);
  EXPECT_NE(
      what.find("element 7 (counted from 0 in file order; tet10, block '" + m.blocks[m.elements[7].block].name + "'"),
      std::string::npos)
      << what;
  EXPECT_NE(what.find("at a Gauss point"), std::string::npos) << what;
  Mesh folded = m;
  Element& el = folded.elements[3];
  // mid-edge node 4 of edge 0-1 moved beyond corner 1 (x4 = x1 + 0.75 (x1 - x0)): the map folds near node 1
  const Vec3d x0 = m.X[el.n[0]], x1 = m.X[el.n[1]];
  folded.X.push_back(x1 + 0.75 * (x1 - x0));
  el.n[4] = int(folded.X.size()) - 1;
  const std::string fold = first_invalid_element(folded);
  EXPECT_NE(fold.find("element 3 "), std::string::npos) << fold;
  EXPECT_NE(fold.find("inverted or degenerate"), std::string::npos) << fold;
  // degenerate: a corner moved into the plane of the other three (det J exactly 0 for a straight tet)
  Mesh flat = m;
  Element& f = flat.elements[5];
  for (int a = 4; a < 10; ++a) {  // straight edges: mid-edge nodes at the midpoints
    static constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}};
    flat.X[f.n[a]] = 0.5 * (flat.X[f.n[kEdge[a - 4][0]]] + flat.X[f.n[kEdge[a - 4][1]]]);
  }
  flat.X.push_back(flat.X[f.n[0]] + 0.5 * (flat.X[f.n[1]] - flat.X[f.n[0]]) + 0.25 * (flat.X[f.n[2]] - flat.X[f.n[0]]));
  f.n[3] = int(flat.X.size()) - 1;
  for (int a : {7, 8, 9}) {  // the edges to corner 3 follow it
    static constexpr int kOther[3] = {0, 2, 1};
    flat.X.push_back(0.5 * (flat.X[f.n[3]] + flat.X[f.n[kOther[a - 7]]]));
    f.n[a] = int(flat.X.size()) - 1;
  }
  const std::string flat_what = first_invalid_element(flat);
  EXPECT_NE(flat_what.find("element 5 "), std::string::npos) << "a flat tet10 is not found: " << flat_what;
  EXPECT_EQ(block_names(m), "media, adventitia");
  EXPECT_NE(surface_names(m, "artery_").find("inner"), std::string::npos);
}
