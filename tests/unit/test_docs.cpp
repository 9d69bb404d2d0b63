// Documentation that cannot rot (issue 19): docs/equations.md names real files, functions and
// tests; the README's and docs' links stay inside the repository and point at files that exist;
// the test harness `experiment selftest` stays out of the user's help.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "../cli_run.hpp"
#include "nipdem/io/atomic_file.hpp"

namespace fs = std::filesystem;

namespace {
const fs::path kRoot = NIPDEM_SOURCE_DIR;

std::vector<std::string> backticked(const std::string& cell) {
  std::vector<std::string> out;
  for (std::size_t a = cell.find('`'); a != std::string::npos; a = cell.find('`', a + 1)) {
    const std::size_t b = cell.find('`', a + 1);
    if (b == std::string::npos) break;
    out.push_back(cell.substr(a + 1, b - a - 1));
    a = b;
  }
  return out;
}

std::vector<std::string> cells(const std::string& row) {
  std::vector<std::string> out;
  std::stringstream ss(row);
  std::string c;
  std::getline(ss, c, '|');  // before the first bar
  while (std::getline(ss, c, '|')) out.push_back(c);
  if (!out.empty() && out.back().find_first_not_of(" \t\r") == std::string::npos) out.pop_back();
  return out;
}

// Every "Suite.Name" declared by TEST / TEST_F / TEST_P in tests/ and validation/.
std::set<std::string> declared_tests() {
  std::set<std::string> names;
  const std::regex decl(R"(TEST(?:_F|_P)?\(\s*(\w+)\s*,\s*(\w+)\s*\))");
  for (const char* dir : {"tests", "validation"})
    for (const auto& e : fs::recursive_directory_iterator(kRoot / dir)) {
      if (e.path().extension() != ".cpp") continue;
      const std::string text = nipdem::io::read_file(e.path());
      for (std::sregex_iterator it(text.begin(), text.end(), decl), end; it != end; ++it)
        names.insert((*it)[1].str() + "." + (*it)[2].str());
    }
  return names;
}
}  // namespace

TEST(DocsIndex, EquationTableNamesRealFilesFunctionsAndTests) {
  const std::string md = nipdem::io::read_file(kRoot / "docs" / "equations.md");
  const auto tests = declared_tests();
  std::stringstream ss(md);
  std::string line;
  int rows = 0;
  while (std::getline(ss, line)) {
    if (line.rfind("| eq", 0) != 0 && line.rfind("| Table", 0) != 0) continue;
    const auto c = cells(line);
    ASSERT_EQ(c.size(), 5u) << "row must have 5 columns: " << line;
    const auto files = backticked(c[2]), functions = backticked(c[3]), names = backticked(c[4]);
    ASSERT_EQ(files.size(), 1u) << line;
    EXPECT_FALSE(functions.empty()) << line;
    EXPECT_FALSE(names.empty()) << line;
    const fs::path file = kRoot / files[0];
    ASSERT_TRUE(fs::exists(file)) << files[0] << " (row: " << c[0] << ")";
    const std::string src = nipdem::io::read_file(file);
    for (const auto& f : functions)
      EXPECT_TRUE(std::regex_search(src, std::regex("\\b" + f + "\\s*\\(")))
          << f << " is not a function in " << files[0] << " (row: " << c[0] << ")";
    for (const auto& t : names) EXPECT_TRUE(tests.count(t)) << "no test " << t << " (row: " << c[0] << ")";
    ++rows;
  }
  EXPECT_GE(rows, 20) << "docs/equations.md: table rows not found (they start with \"| eq\" or \"| Table\")";
}

TEST(DocsLinks, ReadmeAndDocsLinkOnlyToFilesInTheRepository) {
  // Markdown links [text](target) and backticked paths of repository files (docs/..., examples/...,
  // scripts/..., bench/..., data/...) must exist inside the repository; no link leaves it (no
  // "../", no absolute path). Web addresses are not checked here.
  std::vector<fs::path> pages = {kRoot / "README.md"};
  for (const auto& e : fs::directory_iterator(kRoot / "docs"))
    if (e.path().extension() == ".md") pages.push_back(e.path());
  const std::regex link(R"(\]\(([^)\s]+)\))");
  const std::regex path(R"(`((?:docs|examples|scripts|bench|data|tests|validation|src|apps)/[A-Za-z0-9_./-]+)`)");
  int checked = 0;
  for (const auto& page : pages) {
    const std::string text = nipdem::io::read_file(page);
    const fs::path here = page.parent_path();
    for (std::sregex_iterator it(text.begin(), text.end(), link), end; it != end; ++it) {
      std::string target = (*it)[1].str();
      if (target.rfind("http://", 0) == 0 || target.rfind("https://", 0) == 0 || target.rfind("mailto:", 0) == 0) continue;
      target = target.substr(0, target.find('#'));
      if (target.empty()) continue;
      const fs::path resolved = fs::weakly_canonical(here / target);
      const std::string rel = fs::relative(resolved, fs::weakly_canonical(kRoot)).string();
      EXPECT_FALSE(rel.rfind("..", 0) == 0 || fs::path(target).is_absolute()) << page.filename() << ": link leaves the repository: " << target;
      EXPECT_TRUE(fs::exists(resolved)) << page.filename() << ": broken link " << target;
      ++checked;
    }
    for (std::sregex_iterator it(text.begin(), text.end(), path), end; it != end; ++it) {
      std::string p = (*it)[1].str();
      if (p.find('*') != std::string::npos) continue;
      while (!p.empty() && (p.back() == '.' || p.back() == '/')) p.pop_back();
      EXPECT_TRUE(fs::exists(kRoot / p)) << page.filename() << ": names a file that does not exist: " << p;
      ++checked;
    }
    EXPECT_EQ(text.find("../shared/"), std::string::npos) << page.filename() << " points outside the repository (../shared/)";
  }
  EXPECT_GT(checked, 20);
}

TEST(DocsHelp, SelftestIsHiddenFromTheUsersHelp) {
  const auto top = nipdem::test::run_cli("--help", "docs");
  const auto exp = nipdem::test::run_cli("experiment --help", "docs");
  EXPECT_EQ(exp.status, 0);
  EXPECT_EQ(top.out.find("selftest"), std::string::npos);
  EXPECT_EQ(exp.out.find("selftest"), std::string::npos) << exp.out;
  EXPECT_EQ(nipdem::test::run_cli("experiment selftest --help", "docs").status, 0);  // still runs
}
