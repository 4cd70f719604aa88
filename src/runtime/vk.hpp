// Every vkrt source includes Vulkan through this header: the installed headers, the loader–ICD
// interface, and the compat tokens newer than the installed headers.
#pragma once

#include "runtime/vk_compat.h"

#include <vulkan/vk_icd.h>
#include <vulkan/vulkan.h>
