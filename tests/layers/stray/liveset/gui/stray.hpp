// Fixture for the layer check: a folder no liveset_library() declares (must be refused).
#pragma once
