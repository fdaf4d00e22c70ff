// Helpers the option tests share (test_yaml_options, test_mapper_options,
// test_class_table): a reader of a YAML text, the message of the OptionsError a call throws,
// temporary YAML files and the error of loading one as mapper options.
#pragma once

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "common/units.h"
#include "ipm_road_mapper/core/io/yaml_options.h"
#include "ipm_road_mapper/core/mapper/mapper_options.h"

namespace ipm_road_mapper {

inline const std::string kConfigDir = std::string(IRM_SOURCE_DIR) + "/config";

inline OptionsReader ReaderOf(const std::string& yaml) {
  return OptionsReader(YAML::Load(yaml), "");
}

// The message of the OptionsError thrown by `f` ("" and a test failure when none is thrown).
inline std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const OptionsError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected OptionsError, got another exception: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "expected OptionsError, nothing was thrown";
  return "";
}

inline bool StartsWith(const std::string& s, const std::string& prefix) {
  return s.rfind(prefix, 0) == 0;
}

// Writes `yaml` to a fresh temporary file and returns its path.
inline std::string TempYaml(const std::string& name, const std::string& yaml) {
  const std::string path = ::testing::TempDir() + "/irm_" + name + ".yaml";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    ADD_FAILURE() << "cannot write " << path;
    return path;
  }
  std::fputs(yaml.c_str(), f);
  std::fclose(f);
  return path;
}

// The error of LoadMapperOptionsFile on a file holding `yaml`, without the "<path>: " prefix
// (which it checks is there).
inline std::string FileError(const std::string& name, const std::string& yaml) {
  const std::string path = TempYaml(name, yaml);
  const std::string error = ErrorOf([&] { LoadMapperOptionsFile(path); });
  std::remove(path.c_str());
  EXPECT_TRUE(StartsWith(error, path + ": ")) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  return StartsWith(error, path + ": ") ? error.substr(path.size() + 2) : error;
}

}  // namespace ipm_road_mapper
