#pragma once
// Reads back the VTK XML files that io/vtk.hpp writes (binary inline
// base64, UInt64 headers, Float64 / Int64 arrays), so that the analysis tools
// work on the outputs of any finished run without re-running it.
//
// This is not a general VTK reader: it accepts exactly the layout our writer
// produces (which ParaView also reads) and throws std::runtime_error naming
// the file and the element for anything else (compressed or appended data,
// other value types, truncated payloads).
#include <filesystem>
#include <vector>

#include "core/io/vtk.hpp"

namespace sanguis::io {

// A .vtu point cloud written by write_point_cloud_vtu(): points and the
// Float64 / Int64 point arrays in file order.
PointCloud read_point_cloud_vtu(const std::filesystem::path& path);

// A .vtp written by write_polymesh_vtp(): points, lines, polygons and the
// cell arrays (one tuple per line, then one per polygon).
PolyMesh read_polymesh_vtp(const std::filesystem::path& path);

// The frames of a .pvd index, in file order, with dataset paths made
// absolute-or-relative to the current directory (joined to the .pvd's folder).
std::vector<PvdIndex::Entry> read_pvd(const std::filesystem::path& path);

// Lookup helpers; throw std::runtime_error naming the array when it is absent.
const DataArray& find_array(const std::vector<DataArray>& arrays, const std::string& name);
const IntDataArray& find_array(const std::vector<IntDataArray>& arrays, const std::string& name);
bool has_array(const std::vector<DataArray>& arrays, const std::string& name);
bool has_array(const std::vector<IntDataArray>& arrays, const std::string& name);

}  // namespace sanguis::io
