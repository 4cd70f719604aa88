#!/usr/bin/env python3
"""Generates vkrt's feature and property tables from the Vulkan registry (vk.xml).

Outputs, in the output folder:
  vkrt_features.h    enum class Feature (every canonical feature), kFeatureCount, the table types
  vkrt_features.cpp  kFeatureStructs: every structure that extends VkPhysicalDeviceFeatures2 (and
                     VkPhysicalDeviceFeatures itself): sType, size, what makes it available, and its VkBool32 members
                     with the canonical feature each one is; kPropertyStructs: every structure that extends
                     VkPhysicalDeviceProperties2, with where each member's value comes from.

Canonical features: the members of VkPhysicalDeviceFeatures and VkPhysicalDeviceVulkan1{1,2,3}Features; a member of
a structure promoted to Vulkan 1.1-1.3 is the core feature of the same name; other extensions' members are their
own features (named by the member, or by structure and member where two extensions share a member name).

Property members of structures promoted to Vulkan 1.1-1.3 come from VkPhysicalDeviceVulkan1{1,2,3}Properties (the
member of the same name; RENAMES lists the few that differ); other structures are copied whole from the value vkrt
keeps for them (runtime/supported_features.cpp), where it keeps one.

Only structures of the "vulkan" API that need no platform header and belong to no provisional extension are listed.
SUPPLEMENT adds structures newer than the installed registry that vkrt supports (defined in runtime/vk_compat.h).
"""
import re
import sys
import xml.etree.ElementTree as ET

CORE_FEATURES = ["VkPhysicalDeviceFeatures", "VkPhysicalDeviceVulkan11Features", "VkPhysicalDeviceVulkan12Features",
                 "VkPhysicalDeviceVulkan13Features"]
CORE_PROPERTIES = {"VK_VERSION_1_1": "VkPhysicalDeviceVulkan11Properties", "VK_VERSION_1_2": "VkPhysicalDeviceVulkan12Properties",
                   "VK_VERSION_1_3": "VkPhysicalDeviceVulkan13Properties"}
VERSIONS = {"VK_VERSION_1_0": 10, "VK_VERSION_1_1": 11, "VK_VERSION_1_2": 12, "VK_VERSION_1_3": 13}
# Members of promoted property structures whose core name differs.
RENAMES = {("VkPhysicalDeviceSubgroupProperties", "supportedStages"): "subgroupSupportedStages",
           ("VkPhysicalDeviceSubgroupProperties", "supportedOperations"): "subgroupSupportedOperations",
           ("VkPhysicalDeviceSubgroupProperties", "quadOperationsInAllStages"): "subgroupQuadOperationsInAllStages"}
# (struct, sType token, extension, [VkBool32 members]) newer than the installed vk.xml.
SUPPLEMENT = [("VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT",
               "VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_LIBRARY_GROUP_HANDLES_FEATURES_EXT",
               "VK_EXT_pipeline_library_group_handles", ["pipelineLibraryGroupHandles"]),
              ("VkPhysicalDeviceRayTracingPositionFetchFeaturesKHR",
               "VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_POSITION_FETCH_FEATURES_KHR",
               "VK_KHR_ray_tracing_position_fetch", ["rayTracingPositionFetch"])]


def for_vulkan(elem):
    api = elem.get("api")
    return api is None or "vulkan" in api.split(",")


def main():
    registry, out = sys.argv[1], sys.argv[2]
    root = ET.parse(registry).getroot()

    structs = {}  # name -> dict(stype, members: [(type, name)], extends)
    for t in root.find("types"):
        if t.get("category") != "struct" or t.get("alias") or not for_vulkan(t):
            continue
        members, stype = [], None
        for m in t.findall("member"):
            if not for_vulkan(m):
                continue
            mname = m.find("name").text
            mtype = m.find("type").text
            if mname == "sType":
                stype = m.get("values")
            members.append((mtype, mname))
        structs[t.get("name")] = {"stype": stype, "members": members, "extends": (t.get("structextends") or "").split(",")}

    # What provides each structure: a core version, or an extension (and the version it was promoted to).
    provider = {}
    for f in root.findall("feature"):
        if not for_vulkan(f) or f.get("name") not in VERSIONS:
            continue
        for req in f.findall("require"):
            for ty in req.findall("type"):
                provider.setdefault(ty.get("name"), ("core", f.get("name")))
    for ext in root.find("extensions"):
        if "vulkan" not in ext.get("supported", "").split(",") or ext.get("platform") or ext.get("provisional") == "true":
            continue
        for req in ext.findall("require"):
            if not for_vulkan(req):
                continue
            for ty in req.findall("type"):
                provider.setdefault(ty.get("name"), ("ext", ext.get("name"), ext.get("promotedto")))

    def availability(name):
        p = provider.get(name)
        if p is None:
            return None
        if p[0] == "core":
            return ("nullptr", VERSIONS[p[1]])
        promoted = VERSIONS.get(p[2] or "", 0)
        return ('"' + p[1] + '"', promoted)

    feature_structs = [n for n, s in sorted(structs.items()) if "VkPhysicalDeviceFeatures2" in s["extends"] and availability(n)]
    feature_structs = CORE_FEATURES[:1] + feature_structs
    property_structs = [n for n, s in sorted(structs.items()) if "VkPhysicalDeviceProperties2" in s["extends"] and availability(n)]

    def bools(name):
        return [m for t, m in structs[name]["members"] if t == "VkBool32"]

    # Canonical features.
    core_names = []
    for c in CORE_FEATURES:
        core_names += bools(c)
    core_set = set(core_names)
    counts = {}
    for n in feature_structs:
        a = availability(n) if n != "VkPhysicalDeviceFeatures" else ("nullptr", 10)
        if n in CORE_FEATURES:
            continue
        for m in bools(n):
            if a[1] and m in core_set:
                continue
            counts[m] = counts.get(m, 0) + 1
    for n, _, _, ms in SUPPLEMENT:
        for m in ms:
            counts[m] = counts.get(m, 0) + 1
    features = list(dict.fromkeys(core_names))

    def canonical(struct, member, promoted):
        # A promoted structure's member is the core feature of its name; a few promoted extensions' features did not
        # become core features (VK_EXT_4444_formats...): those stay their own.
        if struct in CORE_FEATURES or (promoted and member in core_set):
            return member
        name = member if counts.get(member, 0) <= 1 and member not in core_set else struct[len("VkPhysicalDevice"):] + "_" + member
        if name not in features:
            features.append(name)
        return name

    feature_rows = []
    for n in feature_structs:
        a = ("nullptr", 10) if n == "VkPhysicalDeviceFeatures" else availability(n)
        members = [(m, canonical(n, m, a[1])) for m in bools(n)]
        stype = "VkStructureType(0)" if n == "VkPhysicalDeviceFeatures" else structs[n]["stype"]
        feature_rows.append((n, stype, a[0], a[1], members))
    for n, stype, ext, ms in SUPPLEMENT:
        feature_rows.append((n, stype, '"' + ext + '"', 0, [(m, canonical(n, m, 0)) for m in ms]))

    core_props = {v: [m for _, m in structs[s]["members"]] for v, s in CORE_PROPERTIES.items()}
    property_rows = []
    for n in property_structs:
        a = availability(n)
        members = [m for _, m in structs[n]["members"] if m not in ("sType", "pNext")]
        copies = []
        if n not in CORE_PROPERTIES.values() and a[1] >= 11:
            for m in members:
                src = RENAMES.get((n, m), m)
                for v in ("VK_VERSION_1_1", "VK_VERSION_1_2", "VK_VERSION_1_3"):
                    if src in core_props[v]:
                        copies.append((m, VERSIONS[v] - 10, CORE_PROPERTIES[v], src))
                        break
                else:
                    print(f"gen_features: note: {n}::{m} of a promoted structure has no core property", file=sys.stderr)
        property_rows.append((n, structs[n]["stype"], a[0], a[1], copies))

    with open(f"{out}/vkrt_features.h", "w") as h:
        h.write("// Generated by tools/gen_features.py from vk.xml. Do not edit.\n#pragma once\n\n#include <cstddef>\n#include <cstdint>\n\n")
        h.write('#include "runtime/vk.hpp"\n\nnamespace vkrt {\n\n')
        h.write("enum class Feature : uint16_t {\n")
        for f in features:
            h.write(f"  {f},\n")
        h.write("};\n")
        h.write(f"inline constexpr size_t kFeatureCount = {len(features)};\n")
        h.write("const char* featureName(Feature f);\n\n")
        h.write("struct FeatureMember {\n  uint32_t offset;\n  Feature feature;\n  const char* name;\n};\n")
        h.write("struct FeatureStruct {\n  VkStructureType sType;  // 0 for VkPhysicalDeviceFeatures\n  uint32_t size;\n  const char* name;\n"
                "  const char* extension;   // null: core\n  uint32_t version;         // 10..13: core or promoted to that version; 0: extension only\n"
                "  const FeatureMember* members;\n  uint32_t count;\n};\n")
        h.write("// One member's value: bytes `size` at `offset`, from byte `sourceOffset` of the core structure `source` (11, 12, 13).\n")
        h.write("struct PropertyCopy {\n  uint32_t offset, size;\n  uint32_t source;\n  uint32_t sourceOffset;\n};\n")
        h.write("struct PropertyStruct {\n  VkStructureType sType;\n  uint32_t size;\n  const char* name;\n  const char* extension;\n"
                "  uint32_t version;\n  const PropertyCopy* copies;  // promoted structures; empty for the others (copied whole)\n  uint32_t count;\n};\n\n")
        h.write("extern const FeatureStruct kFeatureStructs[];\nextern const size_t kFeatureStructCount;\n")
        h.write("extern const PropertyStruct kPropertyStructs[];\nextern const size_t kPropertyStructCount;\n\n}  // namespace vkrt\n")

    with open(f"{out}/vkrt_features.cpp", "w") as c:
        c.write("// Generated by tools/gen_features.py from vk.xml. Do not edit.\n#include \"vkrt_features.h\"\n\n")
        c.write("#include <cstddef>\n\nnamespace vkrt {\nnamespace {\n\n")
        for i, (n, stype, ext, ver, members) in enumerate(feature_rows):
            if not members:
                continue
            c.write(f"const FeatureMember kF{i}[] = {{\n")
            for m, f in members:
                c.write(f'    {{offsetof({n}, {m}), Feature::{f}, "{m}"}},\n')
            c.write("};\n")
        for i, (n, stype, ext, ver, copies) in enumerate(property_rows):
            if not copies:
                continue
            c.write(f"const PropertyCopy kP{i}[] = {{\n")
            for m, src, core, srcm in copies:
                c.write(f"    {{offsetof({n}, {m}), sizeof({n}::{m}), {src + 10}, offsetof({core}, {srcm})}},\n")
            c.write("};\n")
        c.write("\nconst char* const kFeatureNames[] = {\n")
        for f in features:
            c.write(f'    "{f}",\n')
        c.write("};\n\n}  // namespace\n\n")
        c.write("const char* featureName(Feature f) { return kFeatureNames[size_t(f)]; }\n\n")
        c.write("const FeatureStruct kFeatureStructs[] = {\n")
        for i, (n, stype, ext, ver, members) in enumerate(feature_rows):
            mem = f"kF{i}, {len(members)}" if members else "nullptr, 0"
            c.write(f'    {{{stype}, sizeof({n}), "{n}", {ext}, {ver}, {mem}}},\n')
        c.write("};\nconst size_t kFeatureStructCount = sizeof(kFeatureStructs) / sizeof(kFeatureStructs[0]);\n\n")
        c.write("const PropertyStruct kPropertyStructs[] = {\n")
        for i, (n, stype, ext, ver, copies) in enumerate(property_rows):
            cp = f"kP{i}, {len(copies)}" if copies else "nullptr, 0"
            c.write(f'    {{{stype}, sizeof({n}), "{n}", {ext}, {ver}, {cp}}},\n')
        c.write("};\nconst size_t kPropertyStructCount = sizeof(kPropertyStructs) / sizeof(kPropertyStructs[0]);\n\n}  // namespace vkrt\n")


if __name__ == "__main__":
    main()
