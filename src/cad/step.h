#pragma once
// STEP (ISO 10303-21) in and out through OCCT's data exchange. Lengths are in the file's own
// unit converted to millimetres (OCCT's default), so a part written and read back keeps its
// coordinates.
#include <TopoDS_Shape.hxx>
#include <string>

namespace glint::cad {

// Every root of the file as one shape. Throws glint::Error(path, "", reason) when the file is
// missing, is not STEP, holds no geometry or the kernel fails on it.
TopoDS_Shape read_step(const std::string& path);

// Writes atomically (temporary file, then rename). Throws glint::Error(path, "", reason).
void write_step(const TopoDS_Shape& shape, const std::string& path);

}  // namespace glint::cad
