#include "dem/domain_decomposition.hpp"
#include "dem/slab_cuts.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numeric>
#include <span>
#include <stdexcept>
#include <type_traits>

namespace sanguis::dem {

struct SlabDecomposition::ParticleRecord {
  std::int64_t id;
  std::uint64_t sort_key;  // ParticleStore::sort_key
  std::int32_t material, species;
  std::uint8_t spherical;
  double radius, mass, inverse_mass;
  Vec3 inertia_body, inverse_inertia_body;
  Quaternion orientation;
  Vec3 position, velocity, angular_velocity;
  Vec3 half_velocity, half_angular;  // leapfrog's mid-step values
  Vec3 force, torque;                // contact force and torque of the last evaluation
};

namespace {

static_assert(std::is_trivially_copyable_v<ContactMemory>);

SlabDecomposition::ParticleRecord record_of(const ParticleStore& p, std::size_t i,
                                            const Vec3& half_velocity, const Vec3& half_angular) {
  return {p.id[i],           p.sort_key[i],
          p.material[i],     p.species[i],
          p.spherical[i],    p.radius[i],
          p.mass[i],         p.inverse_mass[i],
          p.inertia_body[i], p.inverse_inertia_body[i],
          p.orientation[i],  p.position[i],
          p.velocity[i],     p.angular_velocity[i],
          half_velocity,     half_angular,
          p.force[i],        p.torque[i]};
}

void append_record(ParticleStore& store, const SlabDecomposition::ParticleRecord& r) {
  store.id.push_back(r.id);
  store.sort_key.push_back(r.sort_key);
  store.material.push_back(r.material);
  store.radius.push_back(r.radius);
  store.mass.push_back(r.mass);
  store.inverse_mass.push_back(r.inverse_mass);
  store.species.push_back(r.species);
  store.spherical.push_back(r.spherical);
  store.inertia_body.push_back(r.inertia_body);
  store.inverse_inertia_body.push_back(r.inverse_inertia_body);
  store.orientation.push_back(r.orientation);
  store.position.push_back(r.position);
  store.velocity.push_back(r.velocity);
  store.angular_velocity.push_back(r.angular_velocity);
  store.force.push_back(r.force);
  store.torque.push_back(r.torque);
  store.coordination.push_back(0);
}

// Sends buckets[d] to process d; returns what every process sent here, by source.
template <typename T>
std::vector<std::vector<T>> all_to_all(MPI_Comm comm, const std::vector<std::vector<T>>& buckets,
                                       std::int64_t& bytes_sent) {
  static_assert(std::is_trivially_copyable_v<T>);
  const int ranks = static_cast<int>(buckets.size());
  std::vector<long long> send_count(static_cast<std::size_t>(ranks)),
      receive_count(static_cast<std::size_t>(ranks));
  for (int d = 0; d < ranks; ++d) {
    send_count[static_cast<std::size_t>(d)] =
        static_cast<long long>(buckets[static_cast<std::size_t>(d)].size() * sizeof(T));
  }
  MPI_Alltoall(send_count.data(), 1, MPI_LONG_LONG, receive_count.data(), 1, MPI_LONG_LONG, comm);
  std::vector<int> sc(static_cast<std::size_t>(ranks)), rc(static_cast<std::size_t>(ranks)),
      sd(static_cast<std::size_t>(ranks), 0), rd(static_cast<std::size_t>(ranks), 0);
  // MPI counts and displacements are ints: every process stops together when one of them
  // would send or receive 2 GB or more in one exchange.
  long long send_total = 0, receive_total = 0;
  for (std::size_t d = 0; d < sc.size(); ++d) {
    send_total += send_count[d];
    receive_total += receive_count[d];
  }
  int too_big = send_total > INT32_MAX || receive_total > INT32_MAX ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &too_big, 1, MPI_INT, MPI_LOR, comm);
  if (too_big) {
    throw std::runtime_error(
        "domain decomposition: one exchange exceeds 2 GB on a process (a gathered checkpoint "
        "holds at most about 7 million particles)");
  }
  for (std::size_t d = 0; d < sc.size(); ++d) {
    sc[d] = static_cast<int>(send_count[d]);
    rc[d] = static_cast<int>(receive_count[d]);
    if (d > 0) {
      sd[d] = sd[d - 1] + sc[d - 1];
      rd[d] = rd[d - 1] + rc[d - 1];
    }
  }
  std::vector<char> send(static_cast<std::size_t>(sd.back() + sc.back()));
  for (std::size_t d = 0; d < sc.size(); ++d) {
    if (sc[d] > 0)
      std::memcpy(send.data() + sd[d], buckets[d].data(), static_cast<std::size_t>(sc[d]));
    bytes_sent += sc[d];
  }
  std::vector<char> receive(static_cast<std::size_t>(rd.back() + rc.back()));
  MPI_Alltoallv(send.data(), sc.data(), sd.data(), MPI_BYTE, receive.data(), rc.data(), rd.data(),
                MPI_BYTE, comm);
  std::vector<std::vector<T>> out(static_cast<std::size_t>(ranks));
  for (std::size_t s = 0; s < out.size(); ++s) {
    out[s].resize(static_cast<std::size_t>(rc[s]) / sizeof(T));
    if (rc[s] > 0)
      std::memcpy(out[s].data(), receive.data() + rd[s], static_cast<std::size_t>(rc[s]));
  }
  return out;
}

// Adds the lifetime of the timer to a total.
class ScopedTimer {
 public:
  explicit ScopedTimer(double& total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~ScopedTimer() {
    total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  double& total_;
  std::chrono::steady_clock::time_point start_;
};

// Local index by particle id (the storage is in (sort key, id) order, not id order).
class IdIndex {
 public:
  explicit IdIndex(const std::vector<std::int64_t>& ids) : order_(id_order(ids)), ids_(ids) {}
  std::size_t operator()(std::int64_t id) const {
    const auto it = std::lower_bound(order_.begin(), order_.end(), id,
                                     [&](std::uint32_t k, std::int64_t v) { return ids_[k] < v; });
    if (it == order_.end() || ids_[*it] != id) {
      throw std::logic_error("domain decomposition: particle id not found");
    }
    return *it;
  }

 private:
  std::vector<std::uint32_t> order_;
  const std::vector<std::int64_t>& ids_;
};

// Storage order: (sort key, id), as one process sorts (DemSimulation::rebuild_sorted).
bool record_stored_before(const SlabDecomposition::ParticleRecord& a,
                          const SlabDecomposition::ParticleRecord& b) {
  return stored_before(a.sort_key, a.id, b.sort_key, b.id);
}

}  // namespace

SlabDecomposition::SlabDecomposition(MPI_Comm comm, int axis) : comm_(comm), requested_axis_(axis) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &ranks_);
  if (axis < -1 || axis > 2) throw std::invalid_argument("slab axis must be 0, 1, 2 or -1");
  send_lists_.resize(static_cast<std::size_t>(ranks_));
  receive_lists_.resize(static_cast<std::size_t>(ranks_));
}

int SlabDecomposition::owner_of(double c) const {
  // bounds_ is increasing; the last slab takes everything beyond (closed domains).
  const auto it = std::upper_bound(bounds_.begin() + 1, bounds_.end() - 1, c);
  return static_cast<int>(it - (bounds_.begin() + 1));
}

bool SlabDecomposition::near_slab(double c, int slab) const {
  const double lo = bounds_[static_cast<std::size_t>(slab)];
  const double hi = bounds_[static_cast<std::size_t>(slab) + 1];
  const auto distance = [&](double x) { return x < lo ? lo - x : (x > hi ? x - hi : 0.0); };
  double d = distance(c);
  if (periodic_axis_) {
    const double length = axis_max_ - axis_min_;
    d = std::min({d, distance(c - length), distance(c + length)});
  }
  return d < band_;
}

// Slab bounds at equal particle counts, from a histogram of the owned particles along
// the axis summed over the processes (cheap: no particle list travels).
void SlabDecomposition::balance(const ParticleStore& p, const std::vector<std::uint8_t>& ghost) {
  constexpr std::size_t kBins = 4096;
  std::vector<long long> histogram(kBins, 0);
  const double length = axis_max_ - axis_min_;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!ghost.empty() && ghost[i]) continue;
    ++histogram[axis_bin(p.position[i][axis_], axis_min_, length, kBins)];
  }
  MPI_Allreduce(MPI_IN_PLACE, histogram.data(), kBins, MPI_LONG_LONG, MPI_SUM, comm_);
  const std::vector<std::size_t> cut =
      equal_weight_cuts(histogram, static_cast<std::size_t>(ranks_));
  bounds_.resize(cut.size());
  for (std::size_t k = 0; k < cut.size(); ++k) {
    bounds_[k] =
        cut[k] == kBins ? axis_max_ : axis_min_ + length * static_cast<double>(cut[k]) / kBins;
  }
}

DemSetup SlabDecomposition::local_setup(const DemSetup& full) {
  if (full.integrator != IntegratorKind::kLeapfrog) {
    throw std::invalid_argument("several MPI processes need the leapfrog integrator");
  }
  for (const PourSource& src : full.pour) {
    if (src.inserted < src.count) {
      throw std::invalid_argument(
          "pouring during the run is not available on several MPI processes: pour on one, "
          "then restart from its checkpoint on several");
    }
  }
  const Vec3 extent = full.domain.length();
  axis_ = requested_axis_;
  if (axis_ < 0)
    axis_ = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  periodic_axis_ = full.domain.periodic[static_cast<std::size_t>(axis_)];
  axis_min_ = full.domain.min[axis_];
  axis_max_ = full.domain.max[axis_];
  const ParticleStore& p = full.particles;
  // Each process reads the whole setup: the histogram of one is that of all.
  std::vector<std::uint8_t> not_mine(p.size(), static_cast<std::uint8_t>(rank_ != 0));
  balance(p, not_mine);

  DemSetup local = full;
  local.particles = ParticleStore{};
  local.pour.clear();  // all poured (checked above)
  // Every process uses the skin and linked cells one process would (ghosts come later).
  const auto [r_min, r_max] = DemSimulation::radius_bounds(full);
  if (local.skin <= 0.0) local.skin = 0.2 * r_min;
  local.largest_radius = r_max;
  std::vector<std::size_t> order(p.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
  for (std::size_t i : order) {
    Vec3 x = p.position[i];
    full.domain.wrap(x);  // as the first list build will
    if (owner_of(x[axis_]) != rank_) continue;
    local.particles.append_from(p, i);
    local.particles.position.back() = x;
  }
  // The ghost band: every pair that can be a candidate of an owned particle.
  band_ = 2.0 * r_max + local.skin;
  return local;
}

void SlabDecomposition::attach(DemSimulation& simulation) {
  simulation.set_exchange(this);
  // The keys the process computed alone follow its own particles' extent: take those
  // of the whole system, as one process does.
  simulation.assign_sort_keys();
  ParticleStore& p = simulation.particles();
  std::vector<ParticleRecord> owned(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    owned[i] = record_of(p, i, Vec3{}, Vec3{});
  }
  // No contact memory yet: the initial forces are evaluated once, as in one process.
  exchange_ghosts(simulation, std::move(owned), {});
  simulation.refresh_forces();
}

bool SlabDecomposition::any(bool local) {
  const ScopedTimer timer(exchange_seconds_);
  int flag = local ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &flag, 1, MPI_INT, MPI_LOR, comm_);
  return flag != 0;
}

void SlabDecomposition::bounds(Vec3& low, Vec3& high) {
  const ScopedTimer timer(exchange_seconds_);
  double values[6] = {low.x, low.y, low.z, -high.x, -high.y, -high.z};
  MPI_Allreduce(MPI_IN_PLACE, values, 6, MPI_DOUBLE, MPI_MIN, comm_);
  low = {values[0], values[1], values[2]};
  high = {-values[3], -values[4], -values[5]};
}

void SlabDecomposition::refresh_ghosts(DemSimulation& simulation) {
  if (ranks_ == 1) return;
  const ScopedTimer timer(exchange_seconds_);
  ParticleStore& p = simulation.particles();
  // The lists are fixed between rebuilds and both sides know their lengths: point-to-point
  // messages with the processes that share ghosts only (the slab neighbours), no collective.
  if (send_states_.size() != send_lists_.size()) {
    send_states_.resize(send_lists_.size());
    receive_states_.resize(receive_lists_.size());
  }
  std::vector<MPI_Request> requests;
  requests.reserve(2 * static_cast<std::size_t>(ranks_));
  for (std::size_t s = 0; s < receive_lists_.size(); ++s) {
    if (receive_lists_[s].empty()) continue;
    receive_states_[s].resize(receive_lists_[s].size());
    requests.emplace_back();
    MPI_Irecv(receive_states_[s].data(),
              static_cast<int>(receive_states_[s].size() * sizeof(GhostState)), MPI_BYTE,
              static_cast<int>(s), kGhostTag, comm_, &requests.back());
  }
  for (std::size_t d = 0; d < send_lists_.size(); ++d) {
    if (send_lists_[d].empty()) continue;
    std::vector<GhostState>& out = send_states_[d];
    out.clear();
    for (std::uint32_t i : send_lists_[d]) {
      out.push_back({p.orientation[i], p.position[i], p.velocity[i], p.angular_velocity[i]});
    }
    requests.emplace_back();
    MPI_Isend(out.data(), static_cast<int>(out.size() * sizeof(GhostState)), MPI_BYTE,
              static_cast<int>(d), kGhostTag, comm_, &requests.back());
    bytes_sent_ += static_cast<std::int64_t>(out.size() * sizeof(GhostState));
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  for (std::size_t s = 0; s < receive_lists_.size(); ++s) {
    for (std::size_t k = 0; k < receive_lists_[s].size(); ++k) {
      const std::uint32_t i = receive_lists_[s][k];
      const GhostState& state = receive_states_[s][k];
      p.orientation[i] = state.orientation;
      p.position[i] = state.position;
      p.velocity[i] = state.velocity;
      p.angular_velocity[i] = state.angular_velocity;
    }
  }
}

void SlabDecomposition::redistribute(DemSimulation& simulation) {
  const ScopedTimer timer(exchange_seconds_);
  ParticleStore& p = simulation.particles();
  const std::vector<std::uint8_t>& ghost = simulation.ghost_flags();
  auto& half_v = simulation.integrator().half_velocity();
  auto& half_w = simulation.integrator().half_angular_velocity();
  // Wrap first, as the rebuild will (bitwise the same): a particle just past the periodic
  // seam belongs to the slab it wraps into, and its ghosts are chosen from there.
  for (std::size_t i = 0; i < p.size(); ++i) simulation.setup().domain.wrap(p.position[i]);
  balance(p, ghost);

  // Owned particles to their new owners.
  std::vector<std::vector<ParticleRecord>> particle_buckets(static_cast<std::size_t>(ranks_));
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (simulation.is_ghost(i)) continue;
    particle_buckets[static_cast<std::size_t>(owner_of(p.position[i][axis_]))].push_back(
        record_of(p, i, half_v[i], half_w[i]));
  }
  // Contact memories to the new owners of both particles (walls: of the particle).
  std::vector<std::vector<ContactMemory>> contact_buckets(static_cast<std::size_t>(ranks_));
  const IdIndex index_of_id(p.id);
  for (const ContactMemory& r : simulation.export_contacts()) {
    const int a = owner_of(p.position[index_of_id(r.first_id)][axis_]);
    contact_buckets[static_cast<std::size_t>(a)].push_back(r);
    if (r.is_pair()) {
      const int b = owner_of(p.position[index_of_id(r.second_id)][axis_]);
      if (b != a) contact_buckets[static_cast<std::size_t>(b)].push_back(r);
    }
  }
  std::vector<ParticleRecord> owned;
  for (auto& from : all_to_all(comm_, particle_buckets, bytes_sent_)) {
    owned.insert(owned.end(), from.begin(), from.end());
  }
  std::vector<ContactMemory> contacts;
  for (auto& from : all_to_all(comm_, contact_buckets, bytes_sent_)) {
    contacts.insert(contacts.end(), from.begin(), from.end());
  }
  exchange_ghosts(simulation, std::move(owned), std::move(contacts));
}

// Sends copies of the owned particles near other slabs, merges owned and ghosts in
// (sort key, id) order and hands everything to the simulation.
void SlabDecomposition::exchange_ghosts(DemSimulation& simulation,
                                        std::vector<ParticleRecord> owned,
                                        std::vector<ContactMemory> contacts) {
  std::sort(owned.begin(), owned.end(), record_stored_before);
  std::vector<std::vector<ParticleRecord>> buckets(static_cast<std::size_t>(ranks_));
  for (auto& list : send_lists_) list.clear();
  std::vector<std::vector<std::int64_t>> sent_ids(static_cast<std::size_t>(ranks_));
  for (const ParticleRecord& r : owned) {
    for (int d = 0; d < ranks_; ++d) {
      if (d == rank_ || !near_slab(r.position[axis_], d)) continue;
      buckets[static_cast<std::size_t>(d)].push_back(r);
      sent_ids[static_cast<std::size_t>(d)].push_back(r.id);
    }
  }
  const auto received = all_to_all(comm_, buckets, bytes_sent_);

  std::vector<ParticleRecord> all = owned;
  std::vector<std::uint8_t> is_ghost_record(owned.size(), 0);
  for (const auto& from : received) {
    all.insert(all.end(), from.begin(), from.end());
    is_ghost_record.insert(is_ghost_record.end(), from.size(), 1);
  }
  std::vector<std::size_t> order(all.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return record_stored_before(all[a], all[b]); });

  ParticleStore store;
  std::vector<std::uint8_t> ghost;
  std::vector<Vec3> half_v, half_w;
  for (std::size_t k : order) {
    const ParticleRecord& r = all[k];
    append_record(store, r);
    ghost.push_back(is_ghost_record[k]);
    half_v.push_back(r.half_velocity);
    half_w.push_back(r.half_angular);
  }
  // Local indices of what goes out and comes in at each ghost refresh.
  const IdIndex index_of_id(store.id);
  for (std::size_t d = 0; d < sent_ids.size(); ++d) {
    for (std::int64_t id : sent_ids[d]) {
      send_lists_[d].push_back(static_cast<std::uint32_t>(index_of_id(id)));
    }
  }
  ghost_count_ = 0;
  for (std::size_t s = 0; s < received.size(); ++s) {
    receive_lists_[s].clear();
    for (const ParticleRecord& r : received[s]) {
      receive_lists_[s].push_back(static_cast<std::uint32_t>(index_of_id(r.id)));
    }
    ghost_count_ += static_cast<std::int64_t>(received[s].size());
  }
  // A pair next to a slab boundary arrives from both processes that evaluated it, with
  // the same memory: keep one.
  std::sort(contacts.begin(), contacts.end(),
            [](const ContactMemory& a, const ContactMemory& b) { return a.key() < b.key(); });
  contacts.erase(std::unique(contacts.begin(), contacts.end(),
                             [](const ContactMemory& a, const ContactMemory& b) {
                               return a.key() == b.key();
                             }),
                 contacts.end());
  simulation.replace_particles(std::move(store), std::move(ghost), std::move(half_v),
                               std::move(half_w), contacts);
}

DemDiagnostics SlabDecomposition::diagnostics(const DemSimulation& simulation) const {
  DemDiagnostics d = simulation.diagnostics();
  const auto owned = static_cast<double>(d.mobile_particles);
  double sums[5] = {d.kinetic_energy_translational, d.kinetic_energy_rotational,
                    d.mean_velocity * owned, d.mean_angular_velocity * owned, owned};
  MPI_Allreduce(MPI_IN_PLACE, sums, 5, MPI_DOUBLE, MPI_SUM, comm_);
  double maxima[2] = {d.max_velocity, d.max_overlap_ratio};
  MPI_Allreduce(MPI_IN_PLACE, maxima, 2, MPI_DOUBLE, MPI_MAX, comm_);
  long long counts[3] = {d.particle_contacts, d.wall_contacts, d.deep_contacts};
  MPI_Allreduce(MPI_IN_PLACE, counts, 3, MPI_LONG_LONG, MPI_SUM, comm_);
  d.kinetic_energy_translational = sums[0];
  d.kinetic_energy_rotational = sums[1];
  d.mean_velocity = sums[4] > 0 ? sums[2] / sums[4] : 0.0;
  d.mean_angular_velocity = sums[4] > 0 ? sums[3] / sums[4] : 0.0;
  d.mobile_particles = static_cast<std::int64_t>(sums[4]);
  d.max_velocity = maxima[0];
  d.max_overlap_ratio = maxima[1];
  d.particle_contacts = counts[0];
  d.wall_contacts = counts[1];
  d.deep_contacts = counts[2];
  return d;
}

std::vector<SlabDecomposition::ParticleRecord> SlabDecomposition::gather_records(
    const DemSimulation& simulation, int root) const {
  const ParticleStore& p = simulation.particles();
  std::vector<std::vector<ParticleRecord>> buckets(static_cast<std::size_t>(ranks_));
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!simulation.is_ghost(i)) {
      buckets[static_cast<std::size_t>(root)].push_back(record_of(p, i, Vec3{}, Vec3{}));
    }
  }
  std::int64_t ignored = 0;
  std::vector<ParticleRecord> all;
  for (auto& from : all_to_all(comm_, buckets, ignored)) {
    all.insert(all.end(), from.begin(), from.end());
  }
  std::sort(all.begin(), all.end(), record_stored_before);
  return all;
}

void SlabDecomposition::attach_restart(DemSimulation& simulation, const DemSimulation& whole) {
  simulation.set_exchange(this);
  // The owned particles as the checkpoint has them (forces included: the first step's
  // drift uses them), and every memory of the checkpoint (each process keeps its own).
  const ParticleStore& all = whole.particles();
  std::vector<ParticleRecord> owned;
  for (std::size_t i = 0; i < all.size(); ++i) {
    ParticleRecord r = record_of(all, i, {}, {});
    whole.setup().domain.wrap(r.position);  // as local_setup() did
    if (owner_of(r.position[axis_]) == rank_) owned.push_back(r);
  }
  exchange_ghosts(simulation, std::move(owned), whole.export_contacts());
  simulation.set_step_index(whole.step_index());
}

void SlabDecomposition::save_checkpoint(const DemSimulation& simulation, DemSimulation* whole,
                                        const std::filesystem::path& file) const {
  // Memories: each process sends those of the contacts whose first particle it owns (a
  // pair across a boundary is held by both, identically).
  std::vector<std::vector<ContactMemory>> buckets(static_cast<std::size_t>(ranks_));
  const IdIndex index_of_id(simulation.particles().id);
  for (const ContactMemory& m : simulation.export_contacts()) {
    if (!simulation.is_ghost(index_of_id(m.first_id))) buckets[0].push_back(m);
  }
  std::int64_t ignored = 0;
  std::vector<ContactMemory> memories;
  for (auto& from : all_to_all(comm_, buckets, ignored)) {
    memories.insert(memories.end(), from.begin(), from.end());
  }
  const std::vector<ParticleRecord> records = gather_records(simulation, 0);
  std::int64_t step = simulation.step_index();
  if (rank_ != 0) return;
  if (whole == nullptr) throw std::logic_error("save_checkpoint: no whole system on process 0");
  ParticleStore store;
  for (const ParticleRecord& r : records) append_record(store, r);
  std::sort(memories.begin(), memories.end(),
            [](const ContactMemory& a, const ContactMemory& b) { return a.key() < b.key(); });
  const std::size_t n = store.size();
  whole->replace_particles(std::move(store), std::vector<std::uint8_t>(n, 0), std::vector<Vec3>(n),
                           std::vector<Vec3>(n), memories);
  whole->set_step_index(step);
  whole->save_checkpoint(file);
}

}  // namespace sanguis::dem
