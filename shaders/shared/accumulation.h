// How an accumulating technique's dispatch (WVDS, Volume-RIS; tyndall/framework/gpu_accumulation.h) maps its work
// items onto pixels, shared by the shaders and the C++ side that sizes the dispatch.
//
// Work items take the image's groups of 64 pixels from 16 horizontal bands in turn: item group g is group g / 16 of
// band g % 16. Any run of items, the slice a dispatch covers, then samples every band alike and costs the same per
// item. (Slices are sized from the last ones' cost per item; in image order they grew through a cheap sky into a slice
// of the dear rows with the sphere and the box, twice as long as intended.) Within a band the groups stay in order, so
// memory is read as 16 sequential streams. Every pixel is one item's exactly once, so a dispatch's read-modify-write of
// its accumulators never races.
#ifndef TY_SHARED_ACCUMULATION_H
#define TY_SHARED_ACCUMULATION_H

#include "compat.h"

TY_BEGIN

TY_CONST uint kAccumulationGroup = 64u;  // pixels per group (the shaders' local size)
TY_CONST uint kAccumulationBands = 16u;

// Groups of 64 pixels in each band for an image of `pixels` pixels; a dispatch has bands * bandGroups * 64 items.
TY_FUNC uint accumulationBandGroups(uint pixels) {
    return ((pixels + kAccumulationGroup - 1u) / kAccumulationGroup + kAccumulationBands - 1u) / kAccumulationBands;
}

// The pixel of work item `item`; >= the image's pixel count for the items past its end (they add nothing).
TY_FUNC uint accumulationPixel(uint item, uint bandGroups) {
    uint band = (item >> 6u) & 15u, groupInBand = item >> 10u;
    return (band * bandGroups + groupInBand) * kAccumulationGroup + (item & 63u);
}

TY_END

#endif
