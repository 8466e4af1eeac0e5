// The sequential rosbag 2.0 writer (see bag_file_writer.h). Record layout (format 2.0): a record
// is <header length u32><header><data length u32><data>; a header is a list of fields
// <field length u32>name=value, sorted by name as rosbag's std::map writes them. Integers are
// little-endian; a time is sec u32 then nsec u32.
#include "birkhoff_cart/ros/bag_file_writer.h"

#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <fcntl.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <utility>

// Every integer and double goes into the file as the host holds it in memory (append_u32,
// append_value_field): right for the little-endian format only on a little-endian host. A
// big-endian build stops here instead of writing bags that no reader can parse.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "BagFileWriter writes host-order integers into rosbag's little-endian format: "
              "a big-endian host needs byte swaps in append_u32 and append_value_field");

namespace birkhoff_cart {
namespace {

// Record kinds (the "op" field).
constexpr std::uint8_t kOpMessageData = 0x02;
constexpr std::uint8_t kOpFileHeader = 0x03;
constexpr std::uint8_t kOpIndexData = 0x04;
constexpr std::uint8_t kOpChunk = 0x05;
constexpr std::uint8_t kOpChunkInfo = 0x06;
constexpr std::uint8_t kOpConnection = 0x07;
constexpr std::uint32_t kIndexVersion = 1;
constexpr std::uint32_t kChunkInfoVersion = 1;
constexpr std::uint32_t kFileHeaderLength = 4096;  // header + padding of the file header record [bytes]
constexpr char kVersionLine[] = "#ROSBAG V2.0\n";
constexpr int kLz4BlockSizeId = 6;        // rosbag's LZ4Stream
constexpr int kBz2BlockSize100k = 9;      // rosbag's BZ2Stream
constexpr int kBz2WorkFactor = 30;

void append(std::vector<std::uint8_t>& out, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  out.insert(out.end(), bytes, bytes + size);
}

void append_u32(std::vector<std::uint8_t>& out, std::uint32_t value) { append(out, &value, sizeof value); }

void append_time(std::vector<std::uint8_t>& out, const ros::Time& time) {
  append_u32(out, time.sec);
  append_u32(out, time.nsec);
}

/// One header field <length u32>name=value.
void append_field(std::vector<std::uint8_t>& out, const char* name, const void* value, std::size_t size) {
  const std::size_t name_length = std::strlen(name);
  append_u32(out, static_cast<std::uint32_t>(name_length + 1 + size));
  append(out, name, name_length);
  out.push_back('=');
  append(out, value, size);
}

void append_field(std::vector<std::uint8_t>& out, const char* name, const std::string& value) {
  append_field(out, name, value.data(), value.size());
}

template <class T>
void append_value_field(std::vector<std::uint8_t>& out, const char* name, const T& value) {
  append_field(out, name, &value, sizeof value);
}

void append_time_field(std::vector<std::uint8_t>& out, const char* name, const ros::Time& time) {
  const std::uint32_t words[2] = {time.sec, time.nsec};
  append_field(out, name, words, sizeof words);
}

/// Reserves the header's length word; end_header() fills it in.
std::size_t begin_header(std::vector<std::uint8_t>& out) {
  const std::size_t at = out.size();
  append_u32(out, 0);
  return at;
}

void end_header(std::vector<std::uint8_t>& out, std::size_t at) {
  const auto length = static_cast<std::uint32_t>(out.size() - at - sizeof(std::uint32_t));
  std::memcpy(out.data() + at, &length, sizeof length);
}

}  // namespace

const char* BagFileWriter::compression_name(Compression compression) {
  switch (compression) {
    case Compression::kLz4: return "lz4";
    case Compression::kBz2: return "bz2";
    case Compression::kNone: break;
  }
  return "none";
}

BagFileWriter::BagFileWriter(const std::string& path, Compression compression, std::uint32_t chunk_threshold)
    : path_(path), compression_(compression), chunk_threshold_(chunk_threshold) {
  descriptor_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (descriptor_ < 0) throw BagFileError("cannot create " + path + ": " + std::strerror(errno));
  start();
}

BagFileWriter::BagFileWriter(int descriptor, const std::string& path, Compression compression,
                             std::uint32_t chunk_threshold)
    : path_(path), compression_(compression), chunk_threshold_(chunk_threshold) {
  descriptor_ = ::fcntl(descriptor, F_DUPFD_CLOEXEC, 0);
  if (descriptor_ < 0) throw BagFileError("cannot write " + path + ": " + std::strerror(errno));
  start();
}

void BagFileWriter::start() {
  chunk_.reserve(static_cast<std::size_t>(chunk_threshold_) + 64 * 1024);
  records_.reserve(64 * 1024);
  try {
    file_header_position_ = sizeof kVersionLine - 1;
    records_.clear();
    append_file_header(records_);
    write_bytes({{kVersionLine, sizeof kVersionLine - 1}, {records_.data(), records_.size()}});
  } catch (...) {
    ::close(descriptor_);
    descriptor_ = -1;
    throw;
  }
}

BagFileWriter::~BagFileWriter() {
  if (descriptor_ >= 0) ::close(descriptor_);
}

void BagFileWriter::fail(const std::string& what) const {
  throw BagFileError(what + " of " + path_ + ": " + std::strerror(errno));
}

void BagFileWriter::write_bytes(std::initializer_list<std::pair<const void*, std::size_t>> pieces) {
  std::array<iovec, 3> pending{};
  std::size_t count = 0;
  std::size_t total = 0;  // [bytes]
  for (const auto& [data, size] : pieces) {
    if (size == 0) continue;
    pending.at(count++) = iovec{const_cast<void*>(data), size};
    total += size;
  }
  std::size_t first = 0;
  while (first < count) {
    const ssize_t written = ::writev(descriptor_, pending.data() + first, static_cast<int>(count - first));
    if (written < 0) {
      if (errno == EINTR) continue;
      fail("cannot write " + std::to_string(total) + " bytes");
    }
    if (written == 0) {
      errno = EIO;
      fail("cannot write " + std::to_string(total) + " bytes");
    }
    position_ += static_cast<std::uint64_t>(written);
    for (auto left = static_cast<std::size_t>(written); left > 0 && first < count;) {  // a short write
      iovec& piece = pending[first];
      const std::size_t taken = std::min(left, piece.iov_len);
      piece.iov_base = static_cast<std::uint8_t*>(piece.iov_base) + taken;
      piece.iov_len -= taken;
      left -= taken;
      if (piece.iov_len == 0) ++first;
    }
  }
}

void BagFileWriter::write_bytes(const std::vector<std::uint8_t>& bytes) { write_bytes({{bytes.data(), bytes.size()}}); }

void BagFileWriter::append_file_header(std::vector<std::uint8_t>& out) const {
  // Fields in rosbag's (std::map) order: chunk_count, conn_count, index_pos, op.
  const std::uint64_t index_position = index_position_;
  const std::size_t at = begin_header(out);
  append_value_field(out, "chunk_count", static_cast<std::uint32_t>(chunks_.size()));
  append_value_field(out, "conn_count", static_cast<std::uint32_t>(connections_.size()));
  append_value_field(out, "index_pos", index_position);
  append_value_field(out, "op", kOpFileHeader);
  end_header(out, at);
  const std::uint32_t header_length = static_cast<std::uint32_t>(out.size() - at - sizeof(std::uint32_t));
  const std::uint32_t padding = header_length < kFileHeaderLength ? kFileHeaderLength - header_length : 0;
  append_u32(out, padding);
  out.insert(out.end(), padding, static_cast<std::uint8_t>(' '));
}

BagFileWriter::Connection& BagFileWriter::connection_of(const std::string& topic, const char* datatype,
                                                        const char* md5sum, const char* definition) {
  for (Connection& connection : connections_) {
    if (connection.topic != topic) continue;
    if (connection.datatype != datatype) {
      throw BagFileError("bag " + path_ + ": topic " + topic + " was recorded as " + connection.datatype +
                         ", not " + datatype);
    }
    return connection;
  }
  Connection connection;
  connection.id = static_cast<std::uint32_t>(connections_.size());
  connection.topic = topic;
  connection.datatype = datatype;
  connection.md5sum = md5sum;
  connection.definition = definition;
  connections_.push_back(std::move(connection));
  // The connection record, inside the chunk where the topic first appears (as rosbag).
  Connection& added = connections_.back();
  std::size_t at = begin_header(chunk_);  // conn, op, topic
  append_value_field(chunk_, "conn", added.id);
  append_value_field(chunk_, "op", kOpConnection);
  append_field(chunk_, "topic", added.topic);
  end_header(chunk_, at);
  at = begin_header(chunk_);  // the connection header as the record's data: md5sum, message_definition, type
  append_field(chunk_, "md5sum", added.md5sum);
  append_field(chunk_, "message_definition", added.definition);
  append_field(chunk_, "type", added.datatype);
  end_header(chunk_, at);
  return added;
}

std::uint8_t* BagFileWriter::begin_message(const std::string& topic, const char* datatype, const char* md5sum,
                                           const char* definition, const ros::Time& time, std::uint32_t length) {
  if (descriptor_ < 0) throw BagFileError("bag " + path_ + " is closed");
  if (!chunk_open_) {
    chunk_open_ = true;
    open_chunk_.position = position_;
    open_chunk_.start_time = time;
    open_chunk_.end_time = time;
    open_chunk_.counts.clear();
    chunk_.clear();
  }
  Connection& connection = connection_of(topic, datatype, md5sum, definition);
  connection.chunk_index.push_back(IndexEntry{time, static_cast<std::uint32_t>(chunk_.size())});
  if (time > open_chunk_.end_time) {
    open_chunk_.end_time = time;
  } else if (time < open_chunk_.start_time) {
    open_chunk_.start_time = time;
  }
  const std::size_t at = begin_header(chunk_);  // conn, op, time
  append_value_field(chunk_, "conn", connection.id);
  append_value_field(chunk_, "op", kOpMessageData);
  append_time_field(chunk_, "time", time);
  end_header(chunk_, at);
  append_u32(chunk_, length);
  const std::size_t data_at = chunk_.size();
  chunk_.resize(data_at + length);
  return chunk_.data() + data_at;
}

void BagFileWriter::end_message() {
  if (chunk_.size() > chunk_threshold_) write_chunk();
}

void BagFileWriter::write_chunk() {
  if (broken_) throw BagFileError("bag " + path_ + ": an earlier chunk could not be written");
  broken_ = true;  // until this chunk and its index are written whole
  const auto uncompressed_size = static_cast<std::uint32_t>(chunk_.size());
  const std::uint8_t* data = chunk_.data();
  std::uint32_t data_size = uncompressed_size;
  if (compression_ == Compression::kLz4) {
    std::size_t capacity = static_cast<std::size_t>(LZ4_compressBound(static_cast<int>(uncompressed_size))) + 1024;
    while (true) {
      if (compressed_.size() < capacity) compressed_.resize(capacity);
      unsigned int output_size = static_cast<unsigned int>(compressed_.size());
      const int status = roslz4_buffToBuffCompress(reinterpret_cast<char*>(chunk_.data()), uncompressed_size,
                                                   reinterpret_cast<char*>(compressed_.data()), &output_size,
                                                   kLz4BlockSizeId);
      if (status == ROSLZ4_OUTPUT_SMALL) {
        capacity = 2 * compressed_.size();
        continue;
      }
      if (status != ROSLZ4_OK) throw BagFileError("bag " + path_ + ": lz4 compression failed (" + std::to_string(status) + ")");
      data_size = output_size;
      break;
    }
    data = compressed_.data();
  } else if (compression_ == Compression::kBz2) {
    const std::size_t capacity = uncompressed_size + uncompressed_size / 100 + 600;  // bzip2's bound
    if (compressed_.size() < capacity) compressed_.resize(capacity);
    unsigned int output_size = static_cast<unsigned int>(compressed_.size());
    const int status = BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(compressed_.data()), &output_size,
                                                reinterpret_cast<char*>(chunk_.data()), uncompressed_size,
                                                kBz2BlockSize100k, 0, kBz2WorkFactor);
    if (status != BZ_OK) throw BagFileError("bag " + path_ + ": bz2 compression failed (" + std::to_string(status) + ")");
    data_size = output_size;
    data = compressed_.data();
  }

  chunk_header_.clear();
  const std::size_t at = begin_header(chunk_header_);  // compression, op, size
  append_field(chunk_header_, "compression", std::string(compression_name(compression_)));
  append_value_field(chunk_header_, "op", kOpChunk);
  append_value_field(chunk_header_, "size", uncompressed_size);
  end_header(chunk_header_, at);
  append_u32(chunk_header_, data_size);

  // The index records after the chunk: one per connection with messages in it, by id; entries in
  // time order (rosbag's multiset keeps equal times in insertion order: a stable sort).
  records_.clear();
  for (Connection& connection : connections_) {
    std::vector<IndexEntry>& index = connection.chunk_index;
    if (index.empty()) continue;
    const auto earlier = [](const IndexEntry& a, const IndexEntry& b) { return a.time < b.time; };
    if (!std::is_sorted(index.begin(), index.end(), earlier)) std::stable_sort(index.begin(), index.end(), earlier);
    const auto count = static_cast<std::uint32_t>(index.size());
    const std::size_t index_at = begin_header(records_);  // conn, count, op, ver
    append_value_field(records_, "conn", connection.id);
    append_value_field(records_, "count", count);
    append_value_field(records_, "op", kOpIndexData);
    append_value_field(records_, "ver", kIndexVersion);
    end_header(records_, index_at);
    append_u32(records_, 12 * count);
    for (const IndexEntry& entry : index) {
      append_time(records_, entry.time);
      append_u32(records_, entry.offset);
    }
    open_chunk_.counts.emplace_back(connection.id, count);
    index.clear();
  }
  // The chunk record and its index records in one writev(2), nothing held back in a buffer: once
  // it returns they are in the file (what SIGKILL or the second signal's _exit leaves), and a kill
  // during it cuts off at most this chunk, which `rosbag reindex` then drops (it keeps a chunk only
  // with its whole index records).
  write_bytes({{chunk_header_.data(), chunk_header_.size()}, {data, data_size}, {records_.data(), records_.size()}});
  chunks_.push_back(open_chunk_);
  chunk_open_ = false;
  chunk_.clear();
  broken_ = false;
}

void BagFileWriter::close() {
  if (descriptor_ < 0) return;
  if (broken_) {  // a partial chunk is on disk: no index after it (`rosbag reindex` stops there)
    ::close(descriptor_);
    descriptor_ = -1;
    throw BagFileError("bag " + path_ + " left unindexed: a chunk could not be written");
  }
  if (chunk_open_) write_chunk();
  index_position_ = position_;
  records_.clear();
  for (const Connection& connection : connections_) {  // the connection records: conn, op, topic
    std::size_t at = begin_header(records_);
    append_value_field(records_, "conn", connection.id);
    append_value_field(records_, "op", kOpConnection);
    append_field(records_, "topic", connection.topic);
    end_header(records_, at);
    at = begin_header(records_);
    append_field(records_, "md5sum", connection.md5sum);
    append_field(records_, "message_definition", connection.definition);
    append_field(records_, "type", connection.datatype);
    end_header(records_, at);
  }
  for (const ChunkInfo& chunk : chunks_) {  // chunk_pos, count, end_time, op, start_time, ver
    const std::size_t at = begin_header(records_);
    append_value_field(records_, "chunk_pos", chunk.position);
    append_value_field(records_, "count", static_cast<std::uint32_t>(chunk.counts.size()));
    append_time_field(records_, "end_time", chunk.end_time);
    append_value_field(records_, "op", kOpChunkInfo);
    append_time_field(records_, "start_time", chunk.start_time);
    append_value_field(records_, "ver", kChunkInfoVersion);
    end_header(records_, at);
    append_u32(records_, static_cast<std::uint32_t>(8 * chunk.counts.size()));
    for (const auto& [id, count] : chunk.counts) {
      append_u32(records_, id);
      append_u32(records_, count);
    }
  }
  write_bytes(records_);
  // The file header, now with the index position: the bag is complete from here on.
  records_.clear();
  append_file_header(records_);
  const int descriptor = std::exchange(descriptor_, -1);  // closed below on every path
  const ssize_t written =
      ::pwrite(descriptor, records_.data(), records_.size(), static_cast<off_t>(file_header_position_));
  const int write_error = errno;
  if (::close(descriptor) != 0) fail("cannot close");
  if (written != static_cast<ssize_t>(records_.size())) {
    errno = written < 0 ? write_error : EIO;
    fail("cannot write the file header");
  }
}

}  // namespace birkhoff_cart
