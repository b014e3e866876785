// Betti numbers over Z/2: b_i = n_i - rank ∂_i - rank ∂_{i+1}, per connected component.
// rank ∂1 and (on pseudo-manifolds) rank ∂_D by union-find; the spanning forests they find
// are the pivots that clear rows and columns of ∂2 in a 3-map, which is then collapsed and
// reduced (see topology.hpp).
#include <algorithm>

#include "complex.hpp"

namespace sewn::topo {

namespace {

// Sorts v and drops entries that occur an even number of times.
void reduce_mod2(std::vector<std::uint32_t>& v) {
  std::sort(v.begin(), v.end());
  std::size_t out = 0;
  for (std::size_t i = 0; i < v.size();) {
    std::size_t j = i;
    while (j < v.size() && v[j] == v[i]) ++j;
    if ((j - i) % 2 == 1) v[out++] = v[i];
    i = j;
  }
  v.resize(out);
}

// a ^= b for sorted index lists (symmetric difference).
void add_mod2(std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b, std::vector<std::uint32_t>& tmp) {
  tmp.clear();
  std::set_symmetric_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(tmp));
  a.swap(tmp);
}

// Column reduction by lowest row. Returns, per column, the row of its pivot (null for a column
// that reduced to zero). Columns must be sorted; they are reduced in place.
std::vector<std::uint32_t> reduce_columns(std::vector<std::vector<std::uint32_t>>& cols, std::uint32_t nrows,
                                          const std::vector<std::uint8_t>* skip = nullptr) {
  std::vector<std::uint32_t> col_of_pivot(nrows, null), pivot(cols.size(), null);
  std::vector<std::uint32_t> tmp;
  for (std::uint32_t j = 0; j < cols.size(); ++j) {
    if (skip && (*skip)[j]) continue;
    auto& col = cols[j];
    while (!col.empty() && col_of_pivot[col.back()] != null) add_mod2(col, cols[col_of_pivot[col.back()]], tmp);
    if (!col.empty()) {
      col_of_pivot[col.back()] = j;
      pivot[j] = col.back();
    }
  }
  return pivot;
}

// Marks the columns that carry rank: first by elementary collapses (a column or row with a
// single entry is a pivot; its row and column go), then by reduction of what is left.
std::vector<std::uint8_t> rank_columns(std::vector<std::vector<std::uint32_t>>& cols, std::uint32_t nrows) {
  const auto ncols = static_cast<std::uint32_t>(cols.size());
  std::vector<std::uint8_t> is_pivot(ncols, 0), col_dead(ncols, 0), row_dead(nrows, 0);
  std::vector<std::uint32_t> col_cnt(ncols), row_cnt(nrows, 0);
  Csr rows;  // columns of each row
  {
    std::vector<std::uint32_t> entry_row, entry_col;
    for (std::uint32_t j = 0; j < ncols; ++j) {
      col_cnt[j] = static_cast<std::uint32_t>(cols[j].size());
      for (std::uint32_t r : cols[j]) {
        entry_row.push_back(r);
        entry_col.push_back(j);
        ++row_cnt[r];
      }
    }
    rows = Csr::group(nrows, static_cast<std::uint32_t>(entry_row.size()), [&](std::uint32_t e) { return entry_row[e]; });
    for (auto& e : rows.idx) e = entry_col[e];
  }
  std::vector<std::uint32_t> col_queue, row_queue;
  for (std::uint32_t j = 0; j < ncols; ++j) {
    if (col_cnt[j] == 0) col_dead[j] = 1;
    else if (col_cnt[j] == 1) col_queue.push_back(j);
  }
  for (std::uint32_t r = 0; r < nrows; ++r) {
    if (row_cnt[r] == 0) row_dead[r] = 1;
    else if (row_cnt[r] == 1) row_queue.push_back(r);
  }
  auto kill_col = [&](std::uint32_t j) {
    col_dead[j] = 1;
    for (std::uint32_t r : cols[j])
      if (!row_dead[r] && --row_cnt[r] <= 1) {
        if (row_cnt[r] == 0) row_dead[r] = 1;
        else row_queue.push_back(r);
      }
  };
  auto kill_row = [&](std::uint32_t r) {
    row_dead[r] = 1;
    for (const std::uint32_t* p = rows.begin(r); p != rows.end(r); ++p)
      if (const std::uint32_t j = *p; !col_dead[j] && --col_cnt[j] <= 1) {
        if (col_cnt[j] == 0) col_dead[j] = 1;
        else col_queue.push_back(j);
      }
  };
  while (!col_queue.empty() || !row_queue.empty()) {
    if (!col_queue.empty()) {
      const std::uint32_t j = col_queue.back();
      col_queue.pop_back();
      if (col_dead[j] || col_cnt[j] != 1) continue;
      std::uint32_t r = null;
      for (std::uint32_t x : cols[j])
        if (!row_dead[x]) r = x;
      is_pivot[j] = 1;
      kill_col(j);
      kill_row(r);
    } else {
      const std::uint32_t r = row_queue.back();
      row_queue.pop_back();
      if (row_dead[r] || row_cnt[r] != 1) continue;
      std::uint32_t j = null;
      for (const std::uint32_t* p = rows.begin(r); p != rows.end(r); ++p)
        if (!col_dead[*p]) j = *p;
      is_pivot[j] = 1;
      kill_row(r);
      kill_col(j);
    }
  }
  // what the collapses left: the live entries of live columns, reduced
  for (std::uint32_t j = 0; j < ncols; ++j) {
    if (col_dead[j]) {
      cols[j].clear();
      continue;
    }
    std::erase_if(cols[j], [&](std::uint32_t r) { return row_dead[r] != 0; });
  }
  const auto pivot = reduce_columns(cols, nrows, &col_dead);
  for (std::uint32_t j = 0; j < ncols; ++j)
    if (!col_dead[j] && pivot[j] != null) is_pivot[j] = 1;
  return is_pivot;
}

}  // namespace

std::vector<std::uint32_t> compute_homology(const Complex& c, Topology& out) {
  const int D = c.dim;
  const int F = D - 1;
  auto comp_of_cell = [&](const std::vector<std::uint32_t>& comp_of_vertex, int i, std::uint32_t k) {
    return comp_of_vertex[c.cell[0][c.root[static_cast<std::size_t>(i)][k]]];
  };

  // 1) rank ∂1 = n0 - (components of the 1-skeleton); the forest's edges clear rows of ∂2
  UnionFind uf(c.count[0]);
  std::vector<std::uint8_t> tree_edge(c.count[1], 0);
  for (std::uint32_t e = 0; e < c.count[1]; ++e) {
    const std::uint32_t r = c.root[1][e];
    tree_edge[e] = uf.unite(c.cell[0][r], c.cell[0][c.b(r, 1)]) ? 1 : 0;
  }
  std::vector<std::uint32_t> comp_of_vertex(c.count[0]);
  std::uint32_t ncomp = 0;
  {
    std::vector<std::uint32_t> id(c.count[0], null);
    for (std::uint32_t v = 0; v < c.count[0]; ++v) {
      const std::uint32_t r = uf.find(v);
      if (id[r] == null) id[r] = ncomp++;
      comp_of_vertex[v] = id[r];
    }
  }
  out.components.assign(ncomp, {});
  for (std::uint32_t k = 0; k < c.count[0]; ++k)
    if (auto& comp = out.components[comp_of_vertex[k]]; comp.dart.is_null()) comp.dart = Dart(c.root[0][k]);
  std::array<std::vector<std::int64_t>, 5> rank;
  for (auto& r : rank) r.assign(ncomp, 0);
  for (int i = 0; i <= D; ++i)
    for (std::uint32_t k = 0; k < c.count[static_cast<std::size_t>(i)]; ++k)
      ++out.components[comp_of_cell(comp_of_vertex, i, k)].cells[static_cast<std::size_t>(i)];
  for (std::uint32_t e = 0; e < c.count[1]; ++e)
    if (tree_edge[e]) ++rank[1][comp_of_cell(comp_of_vertex, 1, e)];

  // 2) rank ∂D: each facet row holds the top cells on its sides, mod 2
  const std::uint32_t ntop = c.count[static_cast<std::size_t>(D)], nfacet = c.count[static_cast<std::size_t>(F)];
  std::vector<std::uint8_t> cleared(nfacet, 0);  // facet columns of ∂_{D-1} known to reduce to zero
  bool pseudo_manifold = true;
  std::vector<std::uint32_t> tops;
  for (std::uint32_t f = 0; f < nfacet && pseudo_manifold; ++f) {
    tops.clear();
    for (const std::uint32_t* p = c.by_facet.begin(f); p != c.by_facet.end(f); ++p) tops.push_back(c.incidences[*p].top);
    reduce_mod2(tops);
    pseudo_manifold = tops.size() <= 2;
  }
  if (pseudo_manifold) {
    // ∂D transposed is the incidence matrix of the dual graph, a facet on one side joining its
    // top cell to a ground node: its rank is n_D minus the dual components without a free facet
    UnionFind dual(ntop + 1);
    for (std::uint32_t f = 0; f < nfacet; ++f) {
      tops.clear();
      for (const std::uint32_t* p = c.by_facet.begin(f); p != c.by_facet.end(f); ++p) tops.push_back(c.incidences[*p].top);
      reduce_mod2(tops);
      if (tops.empty()) continue;
      if (dual.unite(tops[0], tops.size() == 2 ? tops[1] : ntop)) {
        cleared[f] = 1;
        ++rank[static_cast<std::size_t>(D)][comp_of_cell(comp_of_vertex, D, tops[0])];
      }
    }
  } else {
    std::vector<std::vector<std::uint32_t>> cols(ntop);
    for (const Incidence& in : c.incidences) cols[in.top].push_back(in.facet);
    for (auto& col : cols) reduce_mod2(col);
    const auto pivot = reduce_columns(cols, nfacet);
    for (std::uint32_t t = 0; t < ntop; ++t)
      if (pivot[t] != null) {
        cleared[pivot[t]] = 1;
        ++rank[static_cast<std::size_t>(D)][comp_of_cell(comp_of_vertex, D, t)];
      }
  }

  // 3) 3-maps: rank ∂2 on the rows and columns the forests leave
  if (D == 3) {
    std::vector<std::uint32_t> face_of_col;
    std::vector<std::vector<std::uint32_t>> cols;
    std::vector<std::uint32_t> row_of_edge(c.count[1], null);
    std::uint32_t nrows = 0;
    for (std::uint32_t e = 0; e < c.count[1]; ++e)
      if (!tree_edge[e]) row_of_edge[e] = nrows++;
    for (std::uint32_t f = 0; f < c.count[2]; ++f) {
      if (cleared[f]) continue;
      std::vector<std::uint32_t> col;
      const std::uint32_t r = c.root[2][f];
      std::uint32_t y = r;
      do {
        if (const std::uint32_t row = row_of_edge[c.cell[1][y]]; row != null) col.push_back(row);
        y = c.b(y, 1);
      } while (y != r);
      reduce_mod2(col);
      cols.push_back(std::move(col));
      face_of_col.push_back(f);
    }
    const auto is_pivot = rank_columns(cols, nrows);
    for (std::size_t j = 0; j < cols.size(); ++j)
      if (is_pivot[j]) ++rank[2][comp_of_cell(comp_of_vertex, 2, face_of_col[j])];
  }

  // 4) Betti numbers
  out.total = {};
  for (std::uint32_t k = 0; k < ncomp; ++k) {
    auto& comp = out.components[k];
    for (int i = 0; i <= D; ++i) {
      const auto si = static_cast<std::size_t>(i);
      comp.betti[si] = comp.cells[si] - rank[si][k] - rank[si + 1][k];
      comp.euler += (i % 2 == 0 ? 1 : -1) * comp.cells[si];
      out.total.cells[si] += comp.cells[si];
      out.total.betti[si] += comp.betti[si];
    }
    out.total.euler += comp.euler;
  }
  return comp_of_vertex;
}

}  // namespace sewn::topo
