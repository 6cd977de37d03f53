// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The one union-find of the library: path halving, and the smaller index always becomes
/// the root, so roots (and every numbering derived from them) do not depend on the order of the
/// unions' arguments.
#pragma once

#include <cstdint>
#include <numeric>
#include <vector>

namespace zomefab {

class DisjointSets {
public:
    explicit DisjointSets(size_t n = 0) : mParent(n) {
        std::iota(mParent.begin(), mParent.end(), uint32_t(0));
    }

    size_t size() const { return mParent.size(); }
    uint32_t find(uint32_t x) {
        while (mParent[x] != x) x = mParent[x] = mParent[mParent[x]];
        return x;
    }
    /// Joins the sets of @p a and @p b; the smaller root stays the root.
    void unite(uint32_t a, uint32_t b) {
        a = find(a), b = find(b);
        if (a == b) return;
        if (a < b)
            mParent[b] = a;
        else
            mParent[a] = b;
    }

private:
    std::vector<uint32_t> mParent;
};

}  // namespace zomefab
