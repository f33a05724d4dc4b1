#pragma once
// Values of blocks that live on other ranks in another forest, moved in one MPI_Alltoallv
// (merged_blocks.hpp, coarsened_blocks.hpp): each rank lists, per rank, the items it sends
// there and the items it receives from there, both sides in the same order.

#include <mpi.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

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
