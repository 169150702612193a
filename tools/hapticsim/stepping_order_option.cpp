#include "tools/hapticsim/stepping_order_option.hpp"

namespace hapticsim::cli {

CLI::Option* AddSteppingOrderOption(CLI::App* app, SteppingOrder* order,
                                    const std::string& description) {
  const std::string substeps(SteppingOrderName(SteppingOrder::kSubsteps));
  const std::string threads(SteppingOrderName(SteppingOrder::kThreads));
  return app
      ->add_option_function<std::string>(
          "--order", [order](const std::string& name) { *order = *SteppingOrderNamed(name); },
          description)
      ->default_str(std::string(SteppingOrderName(*order)))
      ->check(CLI::IsMember({substeps, threads}));  // before the function: a known name
}

}  // namespace hapticsim::cli
