// engine/src/box_pair_finder.cpp -- feeding a stage's boxes to its broad phase instance.
#include "box_pair_finder.h"

#include <cmath>
#include <stdexcept>

namespace engine {

collision::ProxyVolumes BoxPairFinder::conservativeVolumes(const collision::Aabb& box) {
    // The centre and half extents are each rounded once; growing the half extents by kSlack
    // times |min| + |max| (at least an ulp of either bound, twice over) keeps the box inside
    // the OBB, and the sphere through the grown OBB's corners, its radius grown by as much
    // again, inside the sphere.
    collision::ProxyVolumes v;
    v.aabb = box;
    v.obb.axes = Mat3::Identity();
    v.obb.center = box.center();
    for (int k = 0; k < 3; ++k) {
        const Real slack = kSlack * (std::abs(box.min[k]) + std::abs(box.max[k]));
        v.obb.half_extents[k] = (box.max[k] - box.min[k]) / 2 + slack;
    }
    v.sphere.center = v.obb.center;
    const Real r = v.obb.half_extents.norm();
    v.sphere.radius = r + kSlack * r;
    return v;
}

void BoxPairFinder::feed(std::span<const collision::Aabb> boxes) {
    if (!phase_) {
        const collision::BroadPhaseEntry* entry = collision::findBroadPhase(name_);
        if (entry == nullptr) {
            throw std::invalid_argument("unknown broad phase '" + name_ + "' (expected one of: " +
                                        collision::broadPhaseNames() + ")");
        }
        phase_ = entry->create();
        phase_->setPairOrder(collision::PairOrder::Sorted);
        decides_on_boxes_ = entry->volume == collision::VolumeKind::Aabb;
        inserted_ = 0;
    }
    const auto present = static_cast<std::ptrdiff_t>(std::min(inserted_, boxes.size()));
    if (decides_on_boxes_) {
        phase_->moveBoxes(0, boxes.first(static_cast<std::size_t>(present)));
        if (boxes.size() > inserted_) {
            phase_->insertBoxes(static_cast<collision::ProxyId>(inserted_),
                                boxes.subspan(inserted_));
        }
    } else {
        scratch_.resize(boxes.size());
        for (std::size_t i = 0; i < boxes.size(); ++i) scratch_[i] = conservativeVolumes(boxes[i]);
        for (std::ptrdiff_t i = 0; i < present; ++i) {
            phase_->move(static_cast<collision::ProxyId>(i),
                         scratch_[static_cast<std::size_t>(i)]);
        }
        if (boxes.size() > inserted_) {
            phase_->insertMany(static_cast<collision::ProxyId>(inserted_),
                               std::span<const collision::ProxyVolumes>(scratch_).subspan(
                                   inserted_));
        }
    }
    inserted_ = boxes.size();
}

}  // namespace engine
