#pragma once
// VTK XML writers for ParaView: particles as .vtu point clouds, obstacles /
// contact networks / membranes as .vtp poly meshes, and the .pvd index that
// turns a series of frames into one time-dependent data set.
//
// Format choices (all fixed, so files from every run look the same):
//  - XML "binary" inline data: each array is one base64 block encoding a
//    UInt64 byte count followed by the raw little-endian values, without
//    compression. Exact (doubles keep every bit), self-contained (one file per
//    frame) and still greppable for the XML structure.
//  - Floating-point arrays are Float64, integer arrays and cell connectivity
//    Int64, cell types UInt8.
//  - Every file is written through write_file_atomically(), so a crashed run
//    never leaves a half-written frame.
//
// Invalid input (array sizes that do not match the number of points/cells,
// empty or duplicate array names, out-of-range point indices) throws
// std::invalid_argument naming the array, before anything is written.
// I/O failures throw std::runtime_error naming the file.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/vec3.hpp"

namespace sanguis::io {

// A Float64 array with `components` values per tuple (1 = scalar, 3 = vector),
// stored tuple by tuple: values.size() must be components * (number of tuples).
struct DataArray {
  std::string name;
  int components = 1;
  std::vector<double> values;
};

// Same as DataArray for Int64 values (ids, species, flags).
struct IntDataArray {
  std::string name;
  int components = 1;
  std::vector<std::int64_t> values;
};

// Particles: one tuple per point in each array.
struct PointCloud {
  std::vector<Vec3> points;
  std::vector<DataArray> point_data;
  std::vector<IntDataArray> int_point_data;
};

// Writes an UnstructuredGrid (.vtu) with one VTK_VERTEX cell per point, so
// ParaView renders the points without a filter. To draw particles apply Glyph
// with a Sphere, scaled by a point array named "radius"; the glyph sphere has
// radius 0.5, so a scale factor of 2 gives spheres of the particle radius.
// Zero points is valid and gives an empty, readable data set.
void write_point_cloud_vtu(const std::filesystem::path& path, const PointCloud& cloud);

// Surfaces and line networks. Each polygon / line lists point indices
// (0-based, into `points`); a polygon needs at least 3, a line (polyline) at
// least 2.
//
// Cell order: VTK numbers PolyData cells as all vertices, then all lines, then
// all polygons (then strips), whatever the order in the file. Cell data
// therefore has one tuple per cell in that order: first one tuple for each
// entry of `lines` (in order), then one for each entry of `polygons`.
struct PolyMesh {
  std::vector<Vec3> points;
  std::vector<std::vector<std::int64_t>> polygons;
  std::vector<std::vector<std::int64_t>> lines;
  std::vector<DataArray> cell_data;
  std::vector<IntDataArray> int_cell_data;
  // Per-point arrays (e.g. nodal forces and curvatures of a membrane): one tuple
  // per entry of `points`.
  std::vector<DataArray> point_data;
};

// Writes a PolyData (.vtp) with the mesh's lines and polygons.
void write_polymesh_vtp(const std::filesystem::path& path, const PolyMesh& mesh);

// Hexahedral cells (block-structured grids): each cell lists its 8 corner
// point indices in VTK_HEXAHEDRON order (the lower z face counter-clockwise
// seen from above, then the upper z face likewise). Cell data has one tuple
// per cell.
struct HexMesh {
  std::vector<Vec3> points;
  std::vector<std::array<std::int64_t, 8>> cells;
  std::vector<DataArray> cell_data;
  std::vector<IntDataArray> int_cell_data;
};

// Writes an UnstructuredGrid (.vtu) of VTK_HEXAHEDRON cells.
void write_hex_mesh_vtu(const std::filesystem::path& path, const HexMesh& mesh);

// One block of a block-structured grid: a box of cells x cells x cells
// cubes of edge `spacing` from `origin` (its lower corner), as VTK
// ImageData. Cell data has one tuple per cell, x fastest, then y, then z.
struct ImageBlock {
  Vec3 origin;
  double spacing = 1.0;
  std::array<int, 3> cells{};
  std::vector<DataArray> cell_data;
  std::vector<IntDataArray> int_cell_data;
};

// Writes an ImageData (.vti) of one block.
void write_image_block_vti(const std::filesystem::path& path, const ImageBlock& block);

// A group of data sets in a multiblock index: its name and, per member, a
// name and the file (relative to the index's folder).
struct MultiblockGroup {
  std::string name;
  std::vector<std::pair<std::string, std::string>> members;  // name, file
};

// Writes a vtkMultiBlockDataSet index (.vtm): one block per group, each
// holding its members' files. ParaView opens it as one data set (its
// Multiblock Inspector lists the groups). Throws std::invalid_argument for
// an empty file name.
void write_multiblock_vtm(const std::filesystem::path& path,
                          const std::vector<MultiblockGroup>& groups);

// A ParaView time-series index (.pvd "Collection"): opening it in ParaView
// loads every frame listed as one data set with a time slider.
//
// Usage: add() one entry per written frame, then write() (cheap; rewriting the
// whole index after each frame keeps it usable while the run is going).
// Dataset paths are stored as given and should be relative to the directory
// of the .pvd file, so that an output folder can be moved as a whole.
class PvdIndex {
 public:
  struct Entry {
    double time = 0.0;
    std::string dataset;  // path relative to the .pvd's directory
    int part = 0;         // several parts at one time = several blocks
  };

  explicit PvdIndex(std::filesystem::path file);

  // Appends an entry; entries are written in insertion order.
  void add(double time, const std::string& relative_dataset_path, int part = 0);

  // Writes the index atomically; times are printed with %.17g so they
  // round-trip exactly through load_existing().
  void write() const;

  // For a restart from a checkpoint at time `up_to_time`: replaces the current
  // entries by those of the existing index file with time <= up_to_time (in
  // file order), so the frames written after the checkpoint are forgotten and
  // the resumed run appends to the right history. A missing file is not an
  // error (no frame was written before the checkpoint): the index becomes
  // empty. Throws std::runtime_error naming the file if it cannot be read or
  // parsed.
  void load_existing(double up_to_time);

  const std::filesystem::path& file() const { return file_; }
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::filesystem::path file_;
  std::vector<Entry> entries_;
};

}  // namespace sanguis::io
