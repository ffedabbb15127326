// Which objects a recipe's outputs need, in which order they are built, and how often each is read,
// so that every level set is built once and released after its last use.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "recipe/recipe.h"

namespace lacuna {

struct Plan {
  std::vector<std::string> inputs;      // inputs to voxelize, in recipe order
  std::vector<std::string> operations;  // operations to evaluate, in recipe order
  std::vector<std::string> exported;    // objects to mesh, in the order the outputs first name them
  std::set<std::string> needed;         // every input and operation built
  std::map<std::string, int> uses;      // how many later operations and outputs read each object
};

// The objects an output writes: its group, or its one object.
std::vector<std::string> members(const RecipeOutput& output);

// What the recipe's outputs (and their material regions) need, through its operations.
Plan plan(const Recipe& recipe);

}  // namespace lacuna
