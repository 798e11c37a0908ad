// src/apps/reduce_seed_lists.cpp — --seed-lists: reading the lists, and the
// comparisons of each (apps/reduce_seed_lists.h).
#include "apps/reduce_seed_lists.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "apps/cli.h"
#include "phnn/report/table_comparisons.h"

namespace phnn {
namespace apps {
namespace {

std::string seeds_text(const std::vector<int>& seeds) {
  std::string out;
  for (std::size_t k = 0; k < seeds.size() && k < 20; ++k) {
    out += (k ? "," : "") + std::to_string(seeds[k]);
  }
  return out + (seeds.size() > 20 ? ",..." : "");
}

// One line's seeds; `where` = "path:line".
std::vector<int> parse_list(const std::string& line, const std::string& where,
                            const std::vector<int>& seeds) {
  std::vector<int> list;
  std::stringstream tokens(line);
  std::string token;
  while (std::getline(tokens, token, ',')) {
    token.erase(0, token.find_first_not_of(" \t\r"));
    token.erase(token.find_last_not_of(" \t\r") + 1);
    const bool digits = !token.empty() && token.size() <= 9 &&
                        token.find_first_not_of("0123456789") == std::string::npos;
    if (!digits) {
      throw cli::UsageError{"phnn reduce: --seed-lists: " + where + ": \"" + token +
                            "\" is not a seed; write one list of seeds per line, e.g. 3,3,0,7"};
    }
    const int seed = std::stoi(token);
    if (!std::binary_search(seeds.begin(), seeds.end(), seed)) {
      throw cli::UsageError{"phnn reduce: --seed-lists: " + where + ": seed " +
                            std::to_string(seed) + " has no run in the tables (their seeds: " +
                            seeds_text(seeds) + "); draw the lists from those"};
    }
    list.push_back(seed);
  }
  return list;
}

}  // namespace

std::vector<std::vector<int>> read_seed_lists(const std::string& path,
                                              const std::vector<int>& seeds) {
  std::ifstream in(path);
  if (!in) {
    throw cli::UsageError{"phnn reduce: --seed-lists " + path + ": cannot be read; give a text "
                          "file with one comma-separated list of seeds per line"};
  }
  std::vector<std::vector<int>> lists;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    lists.push_back(parse_list(line, path + ":" + std::to_string(number), seeds));
  }
  if (lists.empty()) {
    throw cli::UsageError{"phnn reduce: --seed-lists " + path + ": holds no list of seeds; "
                          "write one comma-separated list per line, e.g. 3,3,0,7"};
  }
  return lists;
}

std::string render_seed_list_comparisons(const Grid& grid, const std::vector<TableEntry>& entries,
                                         const std::vector<std::vector<int>>& lists,
                                         const ComparisonOptions& options) {
  std::string out;
  for (std::size_t k = 0; k < lists.size(); ++k) {
    const std::string csv = render_comparisons_csv(
        compare_table_cells(grid, entries_for_seeds(entries, lists[k]), options), options.delta,
        static_cast<int>(k + 1));
    out += k == 0 ? csv : csv.substr(csv.find('\n') + 1);  // one header
  }
  return out;
}

}  // namespace apps
}  // namespace phnn
