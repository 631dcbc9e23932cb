// Umbrella header of the solid_contact library (see solid_solver/contact/README.md).
#pragma once
#include "angio/contact/capsule_tool.hpp"
#include "angio/contact/face.hpp"
#include "angio/contact/line_contact.hpp"
#include "angio/contact/projection.hpp"
#include "angio/contact/search.hpp"
#include "angio/contact/surface_contact.hpp"
