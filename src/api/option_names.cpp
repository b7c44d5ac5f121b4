// The spellings of the option values, each written here once: the command line's
// flags, the stats JSON and the *_name() functions all read these tables.
#include "oocsimp/hierarchy.hpp"
#include "oocsimp/error.hpp"
#include "oocsimp/names.hpp"

namespace oocsimp {

const EnumNames<ClusterMethod>& cluster_method_names() {
  static const EnumNames<ClusterMethod> names = {{ClusterMethod::automatic, "auto"},
                                                 {ClusterMethod::floating, "floating"},
                                                 {ClusterMethod::uniform, "uniform"},
                                                 {ClusterMethod::curvature, "curvature"},
                                                 {ClusterMethod::qem, "qem"}};
  return names;
}

const EnumNames<CellShape>& cell_shape_names() {
  static const EnumNames<CellShape> names = {{CellShape::cube, "cube"}, {CellShape::sphere, "sphere"}};
  return names;
}

const EnumNames<AssignRule>& assign_rule_names() {
  static const EnumNames<AssignRule> names = {{AssignRule::nearest, "nearest"}, {AssignRule::heaviest, "heaviest"}};
  return names;
}

const EnumNames<RepresentativeRule>& representative_rule_names() {
  static const EnumNames<RepresentativeRule> names = {{RepresentativeRule::quadric, "quadric"},
                                                      {RepresentativeRule::centre, "centre"},
                                                      {RepresentativeRule::mean, "mean"},
                                                      {RepresentativeRule::vertex, "vertex"}};
  return names;
}

const EnumNames<SpillCompression>& spill_compression_names() {
  static const EnumNames<SpillCompression> names = {
      {SpillCompression::automatic, "auto"}, {SpillCompression::zstd, "zstd"}, {SpillCompression::none, "none"}};
  return names;
}

const EnumNames<HierarchyPlacement>& hierarchy_placement_names() {
  static const EnumNames<HierarchyPlacement> names = {{HierarchyPlacement::quadric, "quadric"},
                                                      {HierarchyPlacement::kept, "kept"}};
  return names;
}

const EnumNames<RefineMethod>& refine_method_names() {
  static const EnumNames<RefineMethod> names = {{RefineMethod::qem, "qem"}, {RefineMethod::none, "none"}};
  return names;
}

const EnumNames<Precision>& precision_names() {
  static const EnumNames<Precision> names = {
      {Precision::automatic, "auto"}, {Precision::float32, "float"}, {Precision::float64, "double"}};
  return names;
}

namespace {

// A value outside its table (a cast) is spelled as the default, so that the stats
// always have a name to write.
template <class E>
const char* name_or_default(const EnumNames<E>& names, E value) {
  const char* name = name_of(names, value);
  return name ? name : names.front().name;
}

}  // namespace

const char* method_name(ClusterMethod m) {
  if (const char* name = name_of(cluster_method_names(), m)) return name;
  throw UsageError("unknown clustering method");
}
const char* cell_shape_name(CellShape s) { return name_or_default(cell_shape_names(), s); }
const char* assign_name(AssignRule a) { return name_or_default(assign_rule_names(), a); }
const char* representative_name(RepresentativeRule r) { return name_or_default(representative_rule_names(), r); }
const char* spill_compression_name(SpillCompression c) { return name_or_default(spill_compression_names(), c); }
const char* refine_name(RefineMethod r) { return name_or_default(refine_method_names(), r); }
const char* precision_name(Precision p) { return name_or_default(precision_names(), p); }

}  // namespace oocsimp
