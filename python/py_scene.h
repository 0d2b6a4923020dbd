// A scene as Python holds it: the loaded Scene, shared with the renders made from it until it is
// changed (copy on write), and what was asked when it was loaded.
#pragma once

#include <memory>

#include "rvr/core/limits.h"
#include "rvr/core/scene.h"

namespace rvr::python {

struct PyScene {
  std::shared_ptr<Scene> scene;  // renders hold it as const
  Limits limits;                 // checked again at each render, with its options
  double load_seconds = 0.0;

  // The scene to change: a copy first when a render still shares it.
  Scene& edit() {
    if (scene.use_count() > 1) scene = std::make_shared<Scene>(*scene);
    return *scene;
  }
};

}  // namespace rvr::python
