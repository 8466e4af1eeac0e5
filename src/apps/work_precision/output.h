// work_precision: opening the files it writes.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>


namespace birkhoff_cart {
namespace work_precision {

inline std::FILE* open_output(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) throw std::runtime_error("cannot write " + path);
  return file;
}

}  // namespace work_precision
}  // namespace birkhoff_cart
