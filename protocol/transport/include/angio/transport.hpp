#pragma once
// Umbrella header for the zenoh transport wrapper.
#include "angio/transport/bytes.hpp"
#include "angio/transport/config.hpp"
#include "angio/transport/errors.hpp"
#include "angio/transport/liveliness.hpp"
#include "angio/transport/publisher.hpp"
#include "angio/transport/queryable.hpp"
#include "angio/transport/session.hpp"
#include "angio/transport/subscriber.hpp"
