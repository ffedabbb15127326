#include "pipeline/plan.h"

#include <algorithm>

namespace lacuna {

std::vector<std::string> members(const RecipeOutput& output) {
  return output.group.empty() ? std::vector<std::string>{output.object} : output.group;
}

Plan plan(const Recipe& recipe) {
  Plan plan;
  std::map<std::string, std::vector<std::string>> operands_of;
  for (const RecipeOperation& op : recipe.operations) operands_of[op.name] = operands(op.spec);
  std::vector<std::string> stack;
  for (const RecipeOutput& out : recipe.outputs)
    for (const std::string& name : members(out)) stack.push_back(name);
  while (!stack.empty()) {
    std::string name = stack.back();
    stack.pop_back();
    if (!plan.needed.insert(name).second) continue;
    auto op = operands_of.find(name);
    if (op != operands_of.end())
      for (const std::string& o : op->second) stack.push_back(o);
  }
  for (const RecipeOperation& op : recipe.operations)
    if (plan.needed.count(op.name))
      for (const std::string& o : operands_of[op.name]) ++plan.uses[o];
  for (const RecipeOutput& out : recipe.outputs)
    for (const std::string& name : members(out))
      if (std::find(plan.exported.begin(), plan.exported.end(), name) == plan.exported.end()) {
        plan.exported.push_back(name);
        ++plan.uses[name];
      }
  // Material regions of tetrahedral outputs are read after their object is meshed.
  for (const RecipeOutput& out : recipe.outputs)
    for (const std::string& name : out.fea.regions) {
      ++plan.uses[name];
      stack.push_back(name);
    }
  while (!stack.empty()) {
    std::string name = stack.back();
    stack.pop_back();
    if (!plan.needed.insert(name).second) continue;
    auto op = operands_of.find(name);
    if (op != operands_of.end())
      for (const std::string& o : op->second) {
        ++plan.uses[o];
        stack.push_back(o);
      }
  }
  for (const RecipeInput& in : recipe.inputs)
    if (plan.needed.count(in.name)) plan.inputs.push_back(in.name);
  for (const RecipeOperation& op : recipe.operations)
    if (plan.needed.count(op.name)) plan.operations.push_back(op.name);
  return plan;
}

}  // namespace lacuna
