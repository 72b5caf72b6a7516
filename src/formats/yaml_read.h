// Design: typed, validating access to yaml-cpp nodes for the spec's YAML files
// (internal to mocap_formats). Getters throw FieldError{where, what}; every public
// loader runs its body inside guard(), which converts FieldError and any
// YAML::Exception into the one-line Error "<file>: <key path>: <problem> (line N)".
// Exceptions therefore never cross the library boundary, and loaders stay short and
// linear instead of threading Expected through every field.
#pragma once

#include <yaml-cpp/yaml.h>

#include <exception>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "core/types.h"
#include "formats/text_io.h"

namespace mocap::formats_detail {

// Reads and parses a YAML file whose top level must be a map.
// Errors: "<file>: cannot open: <strerror>", "<file>: empty file",
// "<file>: line N: <yaml message>", "<file>: top level: expected a map, got ...".
Expected<YAML::Node> load_yaml_map(const std::string& path);

// Runs fn() (returning T); converts FieldError / YAML::Exception to Error.
template <class T, class F>
Expected<T> guard(const std::string& path, F&& fn) {
  try {
    return fn();
  } catch (const FieldError& e) {
    return make_error(path, e.where, e.what);
  } catch (const YAML::Exception& e) {
    if (e.mark.line >= 0) {
      return make_error(path, "line " + std::to_string(e.mark.line + 1), e.msg);
    }
    return make_error(path, "", e.what());
  } catch (const std::exception& e) {  // e.g. std::bad_alloc on an absurd file
    return make_error(path, "", e.what());
  }
}

// "cameras[1]" + "fx" -> "cameras[1].fx"; "" + "cameras" -> "cameras".
std::string key_path(const std::string& parent, std::string_view key);
std::string index_path(const std::string& parent, std::size_t index);
// " (line N)" for a node that has a position in the file, else "".
std::string line_suffix(const YAML::Node& node);
// "a map", "a list", "nothing", "the text 'abc'".
std::string describe(const YAML::Node& node);

void require_map(const YAML::Node& node, const std::string& where);
void require_list(const YAML::Node& node, const std::string& where);
// Throws when two keys of the map are equal (yaml-cpp would silently keep one).
void check_unique_keys(const YAML::Node& map, const std::string& where);

bool has_key(const YAML::Node& map, std::string_view key);
// The value of `key` in the map at `where`; throws "missing key" when absent.
YAML::Node require_key(const YAML::Node& map, const std::string& where, std::string_view key);

double get_double(const YAML::Node& node, const std::string& where);
std::int64_t get_int(const YAML::Node& node, const std::string& where);
std::string get_string(const YAML::Node& node, const std::string& where);
// A flow or block list of finite numbers; count < 0 accepts any length.
std::vector<double> get_doubles(const YAML::Node& node, const std::string& where, int count);
Vec3 get_vec3(const YAML::Node& node, const std::string& where);

}  // namespace mocap::formats_detail
