#pragma once
// Values of blocks that live on other ranks in another forest, moved in one MPI_Alltoallv
// (merged_blocks.hpp, coarsened_blocks.hpp): where each block goes (route_blocks), then
// each rank lists, per rank, the items it sends there and the items it receives from
// there, both sides in the same order.

#include <mpi.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "flow/forest.hpp"

namespace sanguis::flow {

/// Headers of N numbers, each rank's outgoing[r] sent to rank r in order; returns, per
/// rank, what that rank sent here, in its order. They tell the receiving side which block
/// (and octant) each payload of exchange_payloads() is for.
template <std::size_t N>
std::vector<std::vector<std::array<std::int32_t, N>>> exchange_headers(
    MPI_Comm comm, const std::vector<std::vector<std::array<std::int32_t, N>>>& outgoing) {
  const std::size_t ranks = outgoing.size();
  constexpr int kN = static_cast<int>(N);
  std::vector<int> send_counts(ranks, 0), receive_counts(ranks, 0);
  std::vector<int> send_offsets(ranks, 0), receive_offsets(ranks, 0);
  std::vector<std::int32_t> headers;
  for (std::size_t r = 0; r < ranks; ++r) {
    send_counts[r] = kN * static_cast<int>(outgoing[r].size());
    for (const auto& header : outgoing[r])
      headers.insert(headers.end(), header.begin(), header.end());
  }
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, receive_counts.data(), 1, MPI_INT, comm);
  for (std::size_t r = 1; r < ranks; ++r) {
    send_offsets[r] = send_offsets[r - 1] + send_counts[r - 1];
    receive_offsets[r] = receive_offsets[r - 1] + receive_counts[r - 1];
  }
  std::vector<std::int32_t> received(
      static_cast<std::size_t>(receive_offsets.back() + receive_counts.back()));
  MPI_Alltoallv(headers.data(), send_counts.data(), send_offsets.data(), MPI_INT32_T,
                received.data(), receive_counts.data(), receive_offsets.data(), MPI_INT32_T, comm);
  std::vector<std::vector<std::array<std::int32_t, N>>> incoming(ranks);
  for (std::size_t r = 0; r < ranks; ++r)
    for (int e = 0; e < receive_counts[r]; e += kN) {
      const auto at = static_cast<std::size_t>(receive_offsets[r] + e);
      std::array<std::int32_t, N> header;
      for (std::size_t n = 0; n < N; ++n) header[n] = received[at + n];
      incoming[r].push_back(header);
    }
  return incoming;
}

/// Where one block of this rank goes in another forest: the leaf at (level, coord) there,
/// and a number that travels with it (the octant of a child in its parent).
struct BlockTarget {
  int level = 0;
  std::array<std::int64_t, 3> coord{};
  std::int32_t tag = -1;
};

/// Each block's target found in forest `to`: on this rank, or on the rank p8est's partition
/// markers name (Forest::owner_of), which is sent the target's position once, so that no
/// rank needs the list of all blocks.
struct BlockRoutes {
  /// Per block: its target's local number in `to`, or -1 where it lies on another rank.
  std::vector<std::int32_t> local;
  /// Per rank: the blocks whose target lies there, in block order.
  std::vector<std::vector<std::int32_t>> sent;
  /// Per rank: (local number in `to`, tag) of each block that rank sends here, in its order.
  std::vector<std::vector<std::array<std::int32_t, 2>>> received;
};

/// BlockRoutes of `targets` (one per block of this rank, in order) into `to`; `what` names
/// the caller in the error thrown when a target is no leaf of `to`.
inline BlockRoutes route_blocks(const Forest& to, const std::vector<BlockTarget>& targets,
                                const std::string& what) {
  const auto key = [&to](int level, const std::array<std::int64_t, 3>& c) {
    const auto n = to.blocks_per_direction(level);
    return (static_cast<std::uint64_t>(level) << 58) |
           static_cast<std::uint64_t>((c[2] * n[1] + c[1]) * n[0] + c[0]);
  };
  std::unordered_map<std::uint64_t, std::int32_t> mine;
  for (int b = 0; b < to.local_blocks(); ++b) mine[key(to.block(b).level, to.block(b).coord)] = b;
  const auto ranks = static_cast<std::size_t>(to.ranks());
  BlockRoutes routes;
  routes.local.assign(targets.size(), -1);
  routes.sent.assign(ranks, {});
  routes.received.assign(ranks, {});
  using Header = std::array<std::int32_t, 5>;  // the target's level and coord, tag
  std::vector<std::vector<Header>> headers(ranks);
  for (std::size_t b = 0; b < targets.size(); ++b) {
    const BlockTarget& t = targets[b];
    if (const auto found = mine.find(key(t.level, t.coord)); found != mine.end()) {
      routes.local[b] = found->second;
      continue;
    }
    const int rank = to.owner_of(t.level, t.coord);
    if (rank == to.rank()) throw std::logic_error(what + ": a block has no match");
    routes.sent[static_cast<std::size_t>(rank)].push_back(static_cast<std::int32_t>(b));
    headers[static_cast<std::size_t>(rank)].push_back(
        {t.level, static_cast<std::int32_t>(t.coord[0]), static_cast<std::int32_t>(t.coord[1]),
         static_cast<std::int32_t>(t.coord[2]), t.tag});
  }
  if (ranks == 1) return routes;
  const auto received = exchange_headers(to.comm(), headers);
  for (std::size_t r = 0; r < ranks; ++r)
    for (const Header& h : received[r]) {
      const auto found = mine.find(key(h[0], {h[1], h[2], h[3]}));
      if (found == mine.end()) throw std::logic_error(what + ": a block has no match");
      routes.received[r].push_back({found->second, h[4]});
    }
  return routes;
}

/// The routes as lists of entries Entry{block, target, tag} (an aggregate of three
/// integers): `local` has one per block of this rank (target -1 where it lies on another
/// rank), send[r] those of the blocks whose target rank r holds, in block order, and
/// receive[r] those rank r sends here ({-1, local target, tag}), in its order.
template <typename Entry>
void route_entries(const BlockRoutes& routes, const std::vector<BlockTarget>& targets,
                   std::vector<Entry>& local, std::vector<std::vector<Entry>>& send,
                   std::vector<std::vector<Entry>>& receive) {
  const std::size_t ranks = routes.sent.size();
  local.assign(targets.size(), Entry{-1, -1, -1});
  for (std::size_t b = 0; b < targets.size(); ++b)
    local[b] = Entry{static_cast<std::int32_t>(b), routes.local[b], targets[b].tag};
  send.assign(ranks, {});
  receive.assign(ranks, {});
  for (std::size_t r = 0; r < ranks; ++r) {
    for (const std::int32_t b : routes.sent[r])
      send[r].push_back(local[static_cast<std::size_t>(b)]);
    for (const auto& [target, tag] : routes.received[r])
      receive[r].push_back(Entry{-1, target, tag});
  }
}

/// For every rank r: produce(item, out) packs each item of outgoing[r], in order, into
/// size(item) values; consume(item, in) unpacks each item of incoming[r] from as many.
template <typename Item, typename Size, typename Produce, typename Consume>
void exchange_payloads(MPI_Comm comm, const std::vector<std::vector<Item>>& outgoing,
                       const std::vector<std::vector<Item>>& incoming, Size&& size,
                       Produce&& produce, Consume&& consume) {
  const std::size_t ranks = outgoing.size();
  std::vector<int> send_counts(ranks, 0), receive_counts(ranks, 0);
  std::vector<int> send_offsets(ranks, 0), receive_offsets(ranks, 0);
  for (std::size_t r = 0; r < ranks; ++r) {
    for (const Item& item : outgoing[r]) send_counts[r] += size(item);
    for (const Item& item : incoming[r]) receive_counts[r] += size(item);
    if (r > 0) {
      send_offsets[r] = send_offsets[r - 1] + send_counts[r - 1];
      receive_offsets[r] = receive_offsets[r - 1] + receive_counts[r - 1];
    }
  }
  std::vector<double> packed(static_cast<std::size_t>(send_offsets.back() + send_counts.back()));
  std::vector<double> unpacked(
      static_cast<std::size_t>(receive_offsets.back() + receive_counts.back()));
  std::size_t at = 0;
  for (std::size_t r = 0; r < ranks; ++r)
    for (const Item& item : outgoing[r]) {
      produce(item, packed.data() + at);
      at += static_cast<std::size_t>(size(item));
    }
  MPI_Alltoallv(packed.data(), send_counts.data(), send_offsets.data(), MPI_DOUBLE, unpacked.data(),
                receive_counts.data(), receive_offsets.data(), MPI_DOUBLE, comm);
  at = 0;
  for (std::size_t r = 0; r < ranks; ++r)
    for (const Item& item : incoming[r]) {
      consume(item, unpacked.data() + at);
      at += static_cast<std::size_t>(size(item));
    }
}

}  // namespace sanguis::flow
