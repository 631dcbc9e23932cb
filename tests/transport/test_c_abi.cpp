// The C ABI rejects bad arguments with status codes and a message instead of crashing.
#include <gtest/gtest.h>

#include <string>

#include "angio_zenoh.h"
#include "test_util.hpp"

namespace tt = angio::transport::test;

TEST(TransportCAbi, NullArgumentsAreReportedNotFatal) {
  EXPECT_EQ(az_session_open(nullptr, 0, nullptr, 0, nullptr), AZ_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(az_last_error()).find("NULL"), std::string::npos) << az_last_error();

  az_bytes out{nullptr, 0};
  EXPECT_EQ(az_request(nullptr, "a/b", nullptr, 0, 10, nullptr, nullptr, &out), AZ_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(out.data, nullptr);

  const char* listen[] = {nullptr};
  az_session* s = nullptr;
  EXPECT_EQ(az_session_open(listen, 1, nullptr, 0, &s), AZ_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(s, nullptr);

  // Destructors accept NULL.
  az_bytes_free(nullptr);
  az_bytes_free(&out);
  az_query_drop(nullptr);
  az_queryable_drop(nullptr);
  EXPECT_EQ(az_session_close(nullptr), AZ_OK);
}

TEST(TransportCAbi, BadKeyExpressionIsAnError) {
  tt::TempDir dir;
  const std::string ep = dir.unix_endpoint();
  const char* listen[] = {ep.c_str()};
  az_session* s = nullptr;
  ASSERT_EQ(az_session_open(listen, 1, nullptr, 0, &s), AZ_OK) << az_last_error();
  az_queryable* q = nullptr;
  EXPECT_EQ(az_queryable_declare(s, "bad//key", &q), AZ_ERR);
  EXPECT_EQ(q, nullptr);
  EXPECT_NE(std::string(az_last_error()).find("bad//key"), std::string::npos) << az_last_error();
  az_bytes out{nullptr, 0};
  EXPECT_LT(az_request(s, "", nullptr, 0, 100, nullptr, nullptr, &out), 0);
  EXPECT_EQ(az_session_close(s), AZ_OK);
}
