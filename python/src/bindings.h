#pragma once
// One function per part of the module, each in its own source file.
#include <pybind11/pybind11.h>

namespace glint::python {

void bind_edges(pybind11::module_ m);           // edges.cpp
void bind_io(pybind11::module_ m);              // io.cpp
void bind_denoise(pybind11::module_ m);         // denoise.cpp
void bind_reconstruction(pybind11::module_ m);  // reconstruction.cpp

}  // namespace glint::python
