// MINC's RAS world <-> liveset's LPS (see minc_world.hpp).
#include "liveset/io/minc_world.hpp"

namespace liveset::io_detail {

void flip_ras_lps(std::vector<double>& origin, std::vector<std::vector<double>>& axes) {
    for (std::size_t r = 0; r < 2 && r < origin.size(); ++r) origin[r] = -origin[r];
    for (auto& axis : axes)
        for (std::size_t r = 0; r < 2 && r < axis.size(); ++r) axis[r] = -axis[r];
}

}  // namespace liveset::io_detail
