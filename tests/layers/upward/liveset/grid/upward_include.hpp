// Fixture for the layer check: floor 0 including floor 2 (must be refused).
#pragma once
#include "liveset/segment/window.hpp"
