// Merging independent renders of one image (shards, `tyndall render --shard I/N`) into one estimate: the spp-weighted
// mean of every channel and the pooled variance of the mean (docs/reference.md, "Shards and merging").
#pragma once

#include "tyndall/image/image.h"

#include <string>
#include <vector>

namespace tyndall {

// Merges renders of the same image with independent seeds. Every image must carry the same size, channels, technique,
// view, reference flag, project hash and technique parameters (metadata), a positive spp, and a seed no other carries;
// otherwise an InputError names the file (`paths[i]`) and the field. Per pixel and channel c, with n_i the shards' spp,
// N their sum and m_i their values: c = sum n_i m_i / N. A channel "variance.c" (the variance of the pixel mean c, as
// the reference estimates it from two independent streams) becomes the pooled estimate
//     sum n_i ((m_i - c)^2 + v_i) / (N (2K - 1))
// over the K shards' 2K streams (within- and between-shard terms, in double); K = 1 returns v_1. The metadata is the
// first image's with spp and renderTime summed, and seeds, shards and mergedFrom listing every input.
Image mergeRenders(const std::vector<Image>& images, const std::vector<std::string>& paths);

}  // namespace tyndall
