// The one hand-kept list of the features vkrt supports (supported_features.cpp), over the canonical features of
// the tables generated from vk.xml (tools/gen_features.py, build/generated/vkrt_features.h).
#pragma once

#include <bitset>

#include "vkrt_features.h"

namespace vkrt {

using FeatureSet = std::bitset<kFeatureCount>;

// Every feature vkrt supports.
const FeatureSet& supportedFeatures();

// The table entry of a feature or property structure type, or null for one vkrt does not know.
const FeatureStruct* featureStruct(VkStructureType sType);
const PropertyStruct* propertyStruct(VkStructureType sType);

}  // namespace vkrt
