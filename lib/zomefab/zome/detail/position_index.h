// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Internal: an open-addressing hash set of ball ids keyed by their exact positions (linear
/// probing, backward-shift deletion). A slot is 8 bytes (32 hash bits + id), so the table of a
/// few thousand balls stays in cache; the exact key is compared through the caller's id → position
/// function only when the hash bits agree.
#pragma once

#include <cstdint>
#include <vector>

#include "zomefab/zome/golden.h"

namespace zomefab::zome::detail {

class PositionIndex {
public:
    static constexpr uint32_t kEmpty = 0xFFFFFFFFu;

    size_t size() const { return mSize; }

    /// The id whose position (@p positionOf(id)) equals @p key, or kEmpty.
    template <class PositionOf>
    uint32_t find(const GoldenVector3& key, PositionOf&& positionOf) const {
        if (mSlots.empty()) return kEmpty;
        const uint32_t h = hash32(key);
        for (size_t i = h & mMask;; i = (i + 1) & mMask) {
            const Slot& s = mSlots[i];
            if (s.value == kEmpty) return kEmpty;
            if (s.hash == h && positionOf(s.value) == key) return s.value;
        }
    }

    /// Adds @p value stored at @p key; the key must be absent.
    void insert(const GoldenVector3& key, uint32_t value) {
        if ((mSize + 1) * 2 > mSlots.size()) grow();
        place(hash32(key), value);
        ++mSize;
    }

    /// Removes @p value (stored at @p key).
    void erase(const GoldenVector3& key, uint32_t value) {
        if (mSlots.empty()) return;
        const uint32_t h = hash32(key);
        size_t i = h & mMask;
        while (true) {
            if (mSlots[i].value == kEmpty) return;
            if (mSlots[i].value == value) break;
            i = (i + 1) & mMask;
        }
        // Backward-shift deletion: move later entries of the probe run into the hole unless their
        // home slot lies cyclically in (hole, j].
        size_t hole = i;
        for (size_t j = (i + 1) & mMask; mSlots[j].value != kEmpty; j = (j + 1) & mMask) {
            const size_t home = mSlots[j].hash & mMask;
            const bool homeInRange = hole <= j ? (home > hole && home <= j) : (home > hole || home <= j);
            if (!homeInRange) {
                mSlots[hole] = mSlots[j];
                hole = j;
            }
        }
        mSlots[hole].value = kEmpty;
        --mSize;
    }

private:
    struct Slot {
        uint32_t hash = 0;
        uint32_t value = kEmpty;
    };

    static uint32_t hash32(const GoldenVector3& key) { return uint32_t(GoldenVector3Hash{}(key)); }

    void place(uint32_t h, uint32_t value) {
        size_t i = h & mMask;
        while (mSlots[i].value != kEmpty) i = (i + 1) & mMask;
        mSlots[i] = {h, value};
    }

    void grow() {
        std::vector<Slot> old;
        old.swap(mSlots);
        const size_t capacity = old.empty() ? 64 : old.size() * 2;
        mSlots.assign(capacity, Slot{});
        mMask = capacity - 1;
        for (const Slot& s : old)
            if (s.value != kEmpty) place(s.hash, s.value);
    }

    std::vector<Slot> mSlots;
    size_t mSize = 0;
    size_t mMask = 0;
};

}  // namespace zomefab::zome::detail
