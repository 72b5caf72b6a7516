// Design: the systemd units of deploy/ pass `systemd-analyze verify` (which needs no
// running systemd, but checks that ExecStart's binary exists): the templates are
// instantiated the way deploy/CMakeLists.txt does at install, with the built `mocap` as
// the binary, and verified together. Also checks the unit settings the service relies on.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/support/test_support.h"

namespace mocap::test {
namespace {

std::string instantiate(const std::string& text) {
  std::string s = text;
  const std::string bindir = std::filesystem::path(mocap_binary()).parent_path().string();
  const std::pair<std::string, std::string> subst[] = {{"@MOCAP_BINDIR@", bindir},
                                                       {"@MOCAP_SYSCONFDIR@", "/etc"},
                                                       {"@MOCAP_DOCDIR@", "/usr/share/doc/mocap"}};
  for (const auto& [from, to] : subst) {
    for (std::size_t p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size()))
      s.replace(p, from.size(), to);
  }
  return s;
}

bool have_systemd_analyze() {
  return std::system("command -v systemd-analyze >/dev/null 2>&1") == 0;
}

TEST(SystemdUnits, VerifyPasses) {
  if (!have_systemd_analyze())
    GTEST_SKIP() << "systemd-analyze not installed (Debian package 'systemd'; "
                    "deploy/install-deps.sh installs it)";
  TempDir dir("units");
  for (const char* unit : {"mocap.service", "iox-roudi.service"}) {
    const std::string text = read_file(source_dir() + "/deploy/" + unit + ".in");
    ASSERT_FALSE(text.empty()) << unit;
    write_file(dir.file(unit), instantiate(text));
  }
  FILE* p = popen(("cd " + dir.path() +
                   " && SYSTEMD_LOG_COLOR=0 systemd-analyze verify ./mocap.service "
                   "./iox-roudi.service 2>&1")
                      .c_str(),
                  "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[1024];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int status = pclose(p);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << out;
  EXPECT_EQ(out, "") << out;
}

TEST(SystemdUnits, ServiceSettings) {
  const std::string m = read_file(source_dir() + "/deploy/mocap.service.in");
  const std::string r = read_file(source_dir() + "/deploy/iox-roudi.service.in");
  for (const char* line :
       {"Type=notify\n", "WatchdogSec=", "Restart=on-failure\n", "User=mocap\n", "Group=mocap\n",
        "SupplementaryGroups=video\n", "LimitRTPRIO=", "LimitMEMLOCK=infinity\n",
        "CPUAffinity=", "StateDirectory=mocap\n", "LogsDirectory=mocap\n", "--check-config"})
    EXPECT_NE(m.find(line), std::string::npos) << "mocap.service lacks " << line;
  // The same primary group for RouDi (iceoryx requirement).
  EXPECT_NE(r.find("Group=mocap\n"), std::string::npos);
  // iceoryx needs the host's /tmp and /dev/shm.
  for (const std::string* u : {&m, &r}) {
    EXPECT_EQ(u->find("\nPrivateTmp="), std::string::npos);
    EXPECT_EQ(u->find("\nPrivateDevices="), std::string::npos);
    EXPECT_EQ(u->find("\nRemoveIPC="), std::string::npos);
  }
}

}  // namespace
}  // namespace mocap::test
