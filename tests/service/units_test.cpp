// Design: the systemd units of deploy/ pass `systemd-analyze verify` (which needs no
// running systemd, but checks that ExecStart's binary exists): the templates are
// instantiated the way deploy/CMakeLists.txt does at install, with the built `mocap` as
// the binary, and verified together. Also checks the unit settings the service relies on,
// applies deploy/mocap.sysusers.conf to a scratch root with `systemd-sysusers --root`
// (the shared user/group that iceoryx needs), and the Debian maintainer scripts.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

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
  for (const char* unit : {"mocap.service", "iox-roudi.service", "mocap-node.service"}) {
    const std::string text = read_file(source_dir() + "/deploy/" + unit + ".in");
    ASSERT_FALSE(text.empty()) << unit;
    write_file(dir.file(unit), instantiate(text));
  }
  FILE* p = popen(("cd " + dir.path() +
                   " && SYSTEMD_LOG_COLOR=0 systemd-analyze verify ./mocap.service "
                   "./iox-roudi.service ./mocap-node.service 2>&1")
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
  // The node's unit validates its configuration first, as mocap.service does.
  EXPECT_NE(read_file(source_dir() + "/deploy/mocap-node.service.in")
                .find("\nExecStartPre=@MOCAP_BINDIR@/mocap node --check-config "),
            std::string::npos);
  // The CPU latency request (pipeline.cpu_latency_us): the device is allowed in the unit's
  // closed device policy, and the udev rule gives it to the service's group.
  EXPECT_NE(m.find("\nDeviceAllow=/dev/cpu_dma_latency rw\n"), std::string::npos);
  const std::string rule = read_file(source_dir() + "/deploy/60-mocap-cpu-latency.rules");
  EXPECT_NE(rule.find("\nKERNEL==\"cpu_dma_latency\", GROUP=\"mocap\", MODE=\"0660\"\n"),
            std::string::npos)
      << rule;
  // The same primary group for RouDi (iceoryx requirement).
  EXPECT_NE(r.find("Group=mocap\n"), std::string::npos);
  // iceoryx needs the host's /tmp and /dev/shm.
  for (const std::string* u : {&m, &r}) {
    EXPECT_EQ(u->find("\nPrivateTmp="), std::string::npos);
    EXPECT_EQ(u->find("\nPrivateDevices="), std::string::npos);
    EXPECT_EQ(u->find("\nRemoveIPC="), std::string::npos);
  }
}

// The lines of a colon-separated database (/etc/passwd, /etc/group) as fields.
std::vector<std::vector<std::string>> read_db(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(read_file(path));
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    std::vector<std::string> fields;
    std::istringstream l(line);
    for (std::string f; std::getline(l, f, ':');) fields.push_back(f);
    if (line.back() == ':') fields.emplace_back();
    rows.push_back(fields);
  }
  return rows;
}

const std::vector<std::string>* find_row(const std::vector<std::vector<std::string>>& db,
                                         const std::string& name) {
  for (const auto& r : db)
    if (!r.empty() && r[0] == name) return &r;
  return nullptr;
}

TEST(SystemdUnits, SysusersCreatesTheSharedUserAndGroup) {
  if (std::system("command -v systemd-sysusers >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "systemd-sysusers not installed (Debian package 'systemd')";
  TempDir root("sysusers");
  std::filesystem::create_directories(root.file("etc"));
  std::filesystem::create_directories(root.file("usr/lib/sysusers.d"));
  std::filesystem::copy_file(source_dir() + "/deploy/mocap.sysusers.conf",
                             root.file("usr/lib/sysusers.d/mocap.conf"));
  ASSERT_EQ(std::system(("systemd-sysusers --root=" + root.path() + " >/dev/null 2>&1").c_str()),
            0);
  const auto passwd = read_db(root.file("etc/passwd"));
  const auto group = read_db(root.file("etc/group"));
  const auto* user = find_row(passwd, "mocap");
  const auto* mocap_group = find_row(group, "mocap");
  const auto* video = find_row(group, "video");
  ASSERT_TRUE(user && user->size() == 7u) << read_file(root.file("etc/passwd"));
  ASSERT_TRUE(mocap_group && mocap_group->size() == 4u) << read_file(root.file("etc/group"));
  ASSERT_TRUE(video && video->size() == 4u) << read_file(root.file("etc/group"));
  // The units run User=mocap Group=mocap: the user's primary group is `mocap`, a system id.
  EXPECT_EQ((*user)[3], (*mocap_group)[2]);
  EXPECT_LT(std::stoi((*user)[2]), 1000);
  EXPECT_EQ((*user)[5], "/var/lib/mocap");  // StateDirectory=mocap
  EXPECT_EQ((*user)[6], "/usr/sbin/nologin");
  EXPECT_EQ((*video)[3], "mocap");  // camera device nodes
}

TEST(DebianPackage, MaintainerScriptsParseAndHandleBothUnits) {
  const std::string dir = source_dir() + "/deploy/debian/";
  for (const char* script : {"postinst.in", "prerm", "postrm"}) {
    EXPECT_EQ(std::system(("sh -n " + dir + script).c_str()), 0) << script;
    EXPECT_EQ(read_file(dir + script).rfind("#!/bin/sh\n", 0), 0u) << script;
  }
  for (const char* script : {"prerm", "postrm"})
    EXPECT_NE(
        std::filesystem::status(dir + script).permissions() & std::filesystem::perms::owner_exec,
        std::filesystem::perms::none)
        << script;
  // Removal stops and disables every unit the package ships (no dangling enable links).
  const std::string prerm = read_file(dir + "prerm");
  for (const char* verb : {"systemctl stop ", "systemctl disable "}) {
    const auto p = prerm.find(verb);
    ASSERT_NE(p, std::string::npos) << verb;
    const std::string line = prerm.substr(p, prerm.find('\n', p) - p);
    for (const char* unit : {"mocap.service", "iox-roudi.service", "mocap-node.service"})
      EXPECT_NE(line.find(unit), std::string::npos) << line;
  }
  const std::string postinst = read_file(dir + "postinst.in");
  EXPECT_NE(postinst.find("systemd-sysusers mocap.conf"), std::string::npos);
  // Purge removes systemd's StateDirectory/LogsDirectory of mocap.service.
  EXPECT_NE(read_file(dir + "postrm").find("rm -rf /var/lib/mocap /var/log/mocap"),
            std::string::npos);
}

}  // namespace
}  // namespace mocap::test
