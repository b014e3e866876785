#pragma once
// The smallest valid scene, which the scene tests vary one key at a time.

#include <nlohmann/json.hpp>

namespace sewn::app::test {

inline nlohmann::json minimal() {
  return nlohmann::json::parse(R"({
    "materials": {"steel": {"young": 2e11, "density": 7800}},
    "meshes": [{"type": "hex_grid", "material": "steel", "cells": [4, 1, 1], "size": [1, 0.25, 0.25]}]
  })");
}

}  // namespace sewn::app::test
