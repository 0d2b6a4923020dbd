// The scene format's contract against the analytic shapes' own statement of their keys: every
// shape of shape_list.h states its type name and keys once (scene_fields, scene_field.h), the
// reader and writer go through that statement, and here docs/scene-format.md's table for the
// shape and docs/rvr-scene-1.schema.json's definition of it must say the same: the same keys in
// the same order, which are required, and what each holds (a vector, a non-zero vector, a number
// > 0). A shape added without its documentation, or a key renamed in one place, fails here.
#include <gtest/gtest.h>
#include <stddef.h>

#include <algorithm>
#include <fstream>
#include <initializer_list>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/shapes/scene_field.h"
#include "rvr/core/shapes/shape_list.h"

namespace rvr {
namespace {

struct ShapeKeys {
  std::string type;
  std::vector<SceneField> fields;
};

std::vector<ShapeKeys> analytic_shapes() {
  std::vector<ShapeKeys> shapes;
  auto add = [&](auto shape) {
    ShapeKeys keys{decltype(shape)::kSceneType, {}};
    decltype(shape)::scene_fields(shape,
                                  [&](const SceneField& f, auto&) { keys.fields.push_back(f); });
    shapes.push_back(keys);
  };
#define RVR_ADD_SHAPE(Type, Enumerator, member) add(Type{});
  RVR_ANALYTIC_SHAPES(RVR_ADD_SHAPE)
#undef RVR_ADD_SHAPE
  return shapes;
}

std::string read_text(const std::string& relative) {
  std::ifstream in(std::string(RVR_SOURCE_DIR) + "/" + relative);
  EXPECT_TRUE(in) << relative;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> cells(const std::string& row) {
  std::vector<std::string> out;
  std::stringstream in(row);
  std::string cell;
  std::getline(in, cell, '|');  // before the first bar
  while (std::getline(in, cell, '|')) {
    cell.erase(0, cell.find_first_not_of(' '));
    cell.erase(cell.find_last_not_of(' ') + 1);
    out.push_back(cell);
  }
  return out;
}

// The rows of the first table after the line that starts with `heading`, each by column name.
std::vector<std::vector<std::pair<std::string, std::string>>> table_after(
    const std::string& markdown, const std::string& heading) {
  std::vector<std::vector<std::pair<std::string, std::string>>> rows;
  std::stringstream in(markdown);
  std::string line;
  while (std::getline(in, line) && line.rfind(heading, 0) != 0) {
  }
  while (std::getline(in, line) && line.rfind("|", 0) != 0) {
  }
  const std::vector<std::string> header = cells(line);
  std::getline(in, line);  // |---|---|
  while (std::getline(in, line) && line.rfind("|", 0) == 0) {
    const std::vector<std::string> row = cells(line);
    rows.emplace_back();
    for (size_t c = 0; c < header.size() && c < row.size(); ++c)
      rows.back().emplace_back(header[c], row[c]);
  }
  return rows;
}

std::string column(const std::vector<std::pair<std::string, std::string>>& row,
                   const std::string& name) {
  for (const auto& [column_name, value] : row)
    if (column_name == name) return value;
  return "(no column " + name + ")";
}

TEST(SceneFormatTable, EveryAnalyticShapeIsDocumentedAsItsKeysSay) {
  const std::string doc = read_text("docs/scene-format.md");
  for (const ShapeKeys& shape : analytic_shapes()) {
    SCOPED_TRACE(shape.type);
    EXPECT_NE(doc.find("| `type` | string | required |"), std::string::npos);
    const auto rows = table_after(doc, "**`" + shape.type + "`**");
    ASSERT_EQ(rows.size(), shape.fields.size())
        << "docs/scene-format.md's table of " << shape.type << " has " << rows.size()
        << " keys; the shape states " << shape.fields.size();
    for (size_t k = 0; k < rows.size(); ++k) {
      const SceneField& f = shape.fields[k];
      const std::string key = column(rows[k], "key");
      EXPECT_TRUE(key.size() > 2 && key.front() == '`' && key.back() == '`' &&
                  key.substr(1, key.size() - 2) == f.key)
          << "row " << k << ": " << key << ", the shape's key " << f.key;
      EXPECT_EQ(column(rows[k], "type"), f.kind == SceneFieldKind::Length ? "number" : "vector")
          << f.key;
      EXPECT_EQ(column(rows[k], "required"), f.required ? "yes" : "no") << f.key;
      if (f.kind == SceneFieldKind::Length) {
        EXPECT_NE(column(rows[k], "allowed").find("> 0"), std::string::npos) << f.key;
      }
      if (f.kind == SceneFieldKind::Direction) {
        EXPECT_NE(column(rows[k], "allowed").find("non-zero"), std::string::npos) << f.key;
      }
    }
  }
}

TEST(SceneFormatTable, EveryAnalyticShapeIsInTheSchemaAsItsKeysSay) {
  const nlohmann::ordered_json schema =
      nlohmann::ordered_json::parse(read_text("docs/rvr-scene-1.schema.json"));
  const nlohmann::ordered_json& defs = schema.at("$defs");
  const nlohmann::ordered_json& types = defs.at("object").at("properties").at("type").at("enum");
  for (const ShapeKeys& shape : analytic_shapes()) {
    SCOPED_TRACE(shape.type);
    EXPECT_NE(std::find(types.begin(), types.end(), shape.type), types.end())
        << "the schema's object types lack " << shape.type;
    bool dispatched = false;
    for (const nlohmann::ordered_json& branch : defs.at("object").at("allOf"))
      dispatched |= branch.at("if").at("properties").at("type").at("const") == shape.type &&
                    branch.at("then").at("$ref") == "#/$defs/" + shape.type;
    EXPECT_TRUE(dispatched) << "no allOf branch sends type " << shape.type << " to its definition";
    ASSERT_TRUE(defs.contains(shape.type)) << "no $defs entry for " << shape.type;
    const nlohmann::ordered_json& def = defs.at(shape.type);
    EXPECT_EQ(def.at("additionalProperties"), false);
    std::vector<std::string> keys = {"type", "name", "material", "transform"};
    std::set<std::string> required = {"type"};
    for (const SceneField& f : shape.fields) {
      keys.push_back(f.key);
      if (f.required) required.insert(f.key);
      ASSERT_TRUE(def.at("properties").contains(f.key)) << f.key;
      const nlohmann::ordered_json& p = def.at("properties").at(f.key);
      switch (f.kind) {
        case SceneFieldKind::Point:
          EXPECT_EQ(p.at("$ref"), "#/$defs/vec3") << f.key;
          break;
        case SceneFieldKind::Direction:
          EXPECT_EQ(p.at("$ref"), "#/$defs/nonzero_vec3") << f.key;
          break;
        case SceneFieldKind::Length:
          EXPECT_EQ(p.at("$ref"), "#/$defs/float") << f.key;
          EXPECT_TRUE(p.contains("exclusiveMinimum")) << f.key << " must be > 0";
          break;
      }
    }
    std::vector<std::string> properties;
    for (const auto& [key, value] : def.at("properties").items()) properties.push_back(key);
    EXPECT_EQ(properties, keys);
    const std::vector<std::string> listed = def.at("required");
    EXPECT_EQ(std::set<std::string>(listed.begin(), listed.end()), required);
  }
}

}  // namespace
}  // namespace rvr
