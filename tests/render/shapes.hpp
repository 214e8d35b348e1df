#pragma once
// Analytic test shapes for the render tests: the library's UV sphere (drape/shapes.hpp).
#include "drape/shapes.hpp"
