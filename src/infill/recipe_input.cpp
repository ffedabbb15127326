#include "infill/recipe_input.h"

#include <memory>

#include "errors.h"
#include "infill/lattice.h"
#include "recipe/recipe.h"

namespace lacuna {

void register_infill_inputs() {
  register_input_type(
      {"lattice",
       {"cell", "period_mm", "strut_radius_mm", "min_mm", "max_mm", "fit_to", "grade", "layout", "inset_mm"},
       [](const JsonObject& o, RecipeInput& in) {
         auto options = std::make_shared<LatticeOptions>();
         std::string cell = o.string_or("cell", "cubic");
         if (cell == "cubic") options->cell = LatticeOptions::Cell::kCubic;
         else if (cell == "bcc") options->cell = LatticeOptions::Cell::kBodyCentred;
         else o.fail("cell", "expected \"cubic\" or \"bcc\", got \"" + cell + "\"");
         options->period_mm = o.positive_length("period_mm");
         const bool fitted = o.has("fit_to");
         if (fitted == (o.has("min_mm") || o.has("max_mm"))) o.fail("", "give either \"fit_to\" or \"min_mm\" and \"max_mm\"");
         const std::string layout = o.string_or("layout", "tiled");
         if (layout == "tiled") options->layout = LatticeOptions::Layout::kTiled;
         else if (layout == "scaled") options->layout = LatticeOptions::Layout::kScaled;
         else if (layout == "conforming") options->layout = LatticeOptions::Layout::kConforming;
         else o.fail("layout", "expected \"tiled\", \"scaled\" or \"conforming\", got \"" + layout + "\"");
         const bool conforming = options->layout == LatticeOptions::Layout::kConforming;
         if (conforming && !fitted) o.fail("layout", "a conforming lattice needs \"fit_to\": the hull it conforms to");
         if (o.has("inset_mm")) {
           if (!conforming) o.fail("inset_mm", "only a conforming lattice has an inset");
           options->conform_inset_mm = o.number("inset_mm");
           if (!(options->conform_inset_mm >= 0)) o.fail("inset_mm", "expected a depth of at least 0 mm");
         }
         bool radius_given = true;
         if (o.has("grade")) {
           JsonObject g = o.object("grade");
           g.allow_only({"parameter", "radius_min_mm", "radius_max_mm", "levels", "field", "axis", "from_mm", "to_mm",
                         "points_mm", "falloff_mm", "depth_mm"});
           const std::string parameter = g.string_or("parameter", "radius");
           if (parameter == "radius") {
             options->graded = LatticeOptions::Graded::kRadius;
             options->radius_min_mm = g.positive_length("radius_min_mm");
             options->radius_max_mm = g.positive_length("radius_max_mm");
             radius_given = false;
           } else if (parameter == "level") {
             options->graded = LatticeOptions::Graded::kLevel;
             const uint64_t levels = g.unsigned_integer_or("levels", 1);
             if (levels < 1 || levels > 6) g.fail("levels", "expected 1 to 6 splits of a cell");
             options->levels = int(levels);
           } else {
             g.fail("parameter", "expected \"radius\" or \"level\", got \"" + parameter + "\"");
           }
           GradeField& f = options->grade;
           std::string field = g.string("field");
           if (field == "ramp") {
             f.kind = GradeField::Kind::kRamp;
             f.axis = g.direction_or("axis", Vec3d{0, 0, 1});
             f.from_mm = g.number("from_mm");
             f.to_mm = g.number("to_mm");
             if (f.from_mm == f.to_mm) g.fail("to_mm", "expected a value different from from_mm");
           } else if (field == "points") {
             f.kind = GradeField::Kind::kPoints;
             f.points_mm = g.vec3_list("points_mm");
             if (f.points_mm.empty()) g.fail("points_mm", "expected at least one point");
             f.falloff_mm = g.positive_length("falloff_mm");
           } else if (field == "depth") {
             f.kind = GradeField::Kind::kDepth;
             f.depth_mm = g.positive_length("depth_mm");
             if (!fitted) g.fail("field", "a depth grade needs \"fit_to\": the hull it is measured in");
           } else {
             g.fail("field", "expected \"ramp\", \"points\" or \"depth\", got \"" + field + "\"");
           }
         }
         if (radius_given) options->radius_mm = o.positive_length("strut_radius_mm");
         else if (o.has("strut_radius_mm")) o.fail("strut_radius_mm", "give the radii in \"grade\" when grading the radius");
         if (!fitted) {
           Box3 box;
           box.expand(o.vec3("min_mm"));
           box.expand(o.vec3("max_mm"));
           Vec3d lo = o.vec3("min_mm"), hi = o.vec3("max_mm");
           if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z)) o.fail("max_mm", "expected max_mm > min_mm on every axis");
           try {
             in.geometry.tubes = lattice_tubes(box, *options);
           } catch (const InvalidInput& e) {
             o.fail("", e.what());
           }
           return;
         }
         const std::string hull = o.string("fit_to");
         in.depends_on.push_back(hull);
         const std::string where = o.file() + ": " + o.path();
         in.resolve = [options, hull, where](RecipeInput& self, const RecipeContext& context) {
           LatticeOptions resolved = *options;
           if (resolved.grade.kind == GradeField::Kind::kDepth)
             resolved.grade.depth_of = context.depth_in(hull, resolved.grade.depth_mm);
           if (resolved.layout == LatticeOptions::Layout::kConforming) {
             // Nodes up to a cell outside, and the inset surface, must lie in the field's band.
             const double period = resolved.period_mm;
             resolved.signed_distance_mm = context.signed_distance_in(hull, resolved.conform_inset_mm + period, period);
           }
           try {
             self.geometry.tubes = lattice_tubes(context.box_of(hull), resolved);
           } catch (const InvalidInput& e) {
             throw InvalidInput(where + ": " + e.what());
           }
         };
       }});
}

}  // namespace lacuna
