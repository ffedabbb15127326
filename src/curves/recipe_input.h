// The `curve` recipe input: space-filling curves on a surface as tubes, with an optional base shell.
#pragma once

namespace lacuna {
namespace curves {

void register_recipe_inputs();

}  // namespace curves
}  // namespace lacuna
