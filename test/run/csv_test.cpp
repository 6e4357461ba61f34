// The CSV rows and files every CSV output shares (run's sinks, log export), and the scene totals
// they carry.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "rbsim/csv.hpp"

namespace rbsim {
namespace {

namespace fs = std::filesystem;

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Csv, RowsHoldOneValuePerColumnInShortestRoundTripForm) {
  std::string row;
  const BodyState s{{1.5, -2.0}, 0.1, {3.0, 4.0}, 1e-300};
  const BodyQuantities q{{6.0, 8.0}, -1.0, 0.25, 12.5, 1.0 / 3.0};
  append_body_row(row, 7, 0.07, 1, s, q);
  EXPECT_EQ(row, "7,0.07,1,1.5,-2,0.1,3,4,1e-300,6,8,-1,0.25,12.5,0.3333333333333333\n");
  EXPECT_EQ(std::count(row.begin(), row.end(), ','),
            std::count(kBodyCsvColumns, kBodyCsvColumns + sizeof kBodyCsvColumns, ','));

  std::string energy;
  Energy e;
  e.u_gravity = -1.0;
  e.u_spring = 0.5;
  e.t_point = 2.0;
  e.t_spin = 0.25;
  append_energy_row(energy, 3, 0.5, e, SceneTotals{{1.0, -1.0}, 2.0});
  EXPECT_EQ(energy, "3,0.5,-0.5,2,0.25,2.25,1.75,-1,0.5,1,-1,2\n");
  EXPECT_EQ(std::count(energy.begin(), energy.end(), ','),
            std::count(kEnergyCsvColumns, kEnergyCsvColumns + sizeof kEnergyCsvColumns, ','));
}

TEST(Csv, WriterWritesTheHeaderThenTheRowsAndAppearsOnlyOnCommit) {
  const fs::path dir = fs::temp_directory_path() / ("rbsim_csv_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / "out.csv";
  {
    CsvWriter csv;
    EXPECT_FALSE(csv.is_open());
    ASSERT_TRUE(csv.open(path.string(), kEnergyCsvColumns).ok());
    EXPECT_TRUE(csv.is_open());
    append_int(csv.rows(), -42);
    csv.rows() += '\n';
    ASSERT_TRUE(csv.flush_if_full().ok());
    EXPECT_FALSE(fs::exists(path));
    ASSERT_TRUE(csv.commit().ok());
  }
  EXPECT_EQ(read_all(path), std::string(kEnergyCsvColumns) + "\n-42\n");
  CsvWriter unopened;
  EXPECT_TRUE(unopened.commit().ok());  // an output not asked for
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rbsim
