#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "core/regions/stepping_order.hpp"

namespace hapticsim::cli {

/**
 * `--order substeps|threads` into `order` (SteppingOrder), its default what `order` holds:
 * `simulate` and `sweep` step the regions in the order it names. A name that is neither is
 * refused by CLI11, naming the option and the two allowed.
 */
CLI::Option* AddSteppingOrderOption(CLI::App* app, SteppingOrder* order,
                                    const std::string& description);

}  // namespace hapticsim::cli
