// A rosbag format 2.0 writer (http://wiki.ros.org/Bags/Format/2.0) for the node's record, written
// sequentially: no seek per message. rosbag::Bag seeks to the end of the file twice before every
// message record (fseeko + ftello: an lseek, an fstat and a read refilling stdio's buffer), which
// cost as much CPU as the whole simulation (docs/benchmarks.md, "Node cost"). Here a chunk is
// assembled in memory (connection and message-data records, exactly as rosbag lays them out),
// compressed once when it passes the chunk threshold, and written with its index records in one
// go; close() appends the connection and chunk-info records and fills in the file header.
//
// The file is byte for byte what rosbag::Bag writes for the same calls without compression (the
// unit test bag_file_writer_test compares them); with lz4 or bz2 the chunks are compressed in one
// piece (roslz4 block size 6, bzip2 level 9 as rosbag), so `rosbag info` and rosbag::View read it
// as any bag, without reindexing.
//
// The file is written with plain write(2) calls, nothing held in a user-space buffer: each chunk
// goes out with its index records in one writev(2) when it is finished, so the file always ends
// in whole chunks plus, at most, a cut-off one. A process killed at any moment (SIGKILL, the
// second signal's _exit) loses only the chunk still in memory, and `rosbag reindex` recovers
// every chunk finished before (it drops a chunk whose index records are cut short).
// A write error (disk full) throws BagFileError when a chunk is written; the chunks already on disk
// stay, the file header still says "unindexed" (index_pos 0) and `rosbag reindex` recovers them.
// Not thread-safe: one thread writes (BagRecorder's writer thread). No allocation per message once
// the chunk buffer and the per-connection indexes have reached their working size.
#pragma once

#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <utility>
#include <stdexcept>
#include <string>
#include <vector>

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <ros/time.h>

namespace birkhoff_cart {

/// The bag file cannot be opened or written (the message names the path and the reason).
class BagFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class BagFileWriter {
 public:
  enum class Compression { kNone, kLz4, kBz2 };
  /// rosbag::Bag's default: a chunk is closed once its uncompressed data passes this [bytes].
  static constexpr std::uint32_t kDefaultChunkThreshold = 768 * 1024;

  /// Creates (truncates) `path` and writes the version line and an unindexed file header. Throws
  /// BagFileError naming the path and the reason.
  BagFileWriter(const std::string& path, Compression compression,
                std::uint32_t chunk_threshold = kDefaultChunkThreshold);
  /// Writes into the open, empty file `descriptor` (a copy of it: the caller keeps its own, and
  /// with it a lock it holds on the file), known as `path` in messages. Throws BagFileError.
  BagFileWriter(int descriptor, const std::string& path, Compression compression,
                std::uint32_t chunk_threshold = kDefaultChunkThreshold);
  /// Closes the file handle; without a successful close() the file stays unindexed.
  ~BagFileWriter();
  BagFileWriter(const BagFileWriter&) = delete;
  BagFileWriter& operator=(const BagFileWriter&) = delete;

  /// Appends one message record on `topic` at `time` (the record's time and index time). A topic's
  /// first message defines its connection (type, md5sum, definition); a later message of another
  /// type on the same topic throws BagFileError. Throws BagFileError when a chunk cannot be written.
  template <class M>
  void write(const std::string& topic, const ros::Time& time, const M& message) {
    namespace serialization = ros::serialization;
    const std::uint32_t length = serialization::serializationLength(message);
    std::uint8_t* data = begin_message(topic, ros::message_traits::datatype(message),
                                       ros::message_traits::md5sum(message), ros::message_traits::definition(message),
                                       time, length);
    serialization::OStream stream(data, length);
    serialization::serialize(stream, message);
    end_message();
  }

  /// Writes the open chunk, the connection and chunk-info records and the final file header, then
  /// closes the file. Throws BagFileError when any of it fails (the file is then left unindexed).
  void close();
  bool is_open() const { return descriptor_ >= 0; }
  const std::string& path() const { return path_; }

  /// "lz4", "bz2", "none" as rosbag names the chunk compressions.
  static const char* compression_name(Compression compression);

 private:
  struct IndexEntry {
    ros::Time time;
    std::uint32_t offset;  ///< of the message-data record in the chunk's uncompressed data [bytes]
  };
  struct Connection {
    std::uint32_t id;
    std::string topic;
    std::string datatype;
    std::string md5sum;
    std::string definition;
    std::vector<IndexEntry> chunk_index;  ///< this connection's messages in the open chunk
  };
  struct ChunkInfo {
    std::uint64_t position;  ///< of the chunk record in the file [bytes]
    ros::Time start_time;
    ros::Time end_time;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> counts;  ///< (connection id, messages)
  };

  /// Opens a chunk if none is, adds the connection record of a new topic, the index entry and the
  /// message record's header; returns where the `length` bytes of serialized message go.
  std::uint8_t* begin_message(const std::string& topic, const char* datatype, const char* md5sum,
                              const char* definition, const ros::Time& time, std::uint32_t length);
  /// Closes the chunk once it passes the threshold.
  void end_message();
  Connection& connection_of(const std::string& topic, const char* datatype, const char* md5sum,
                            const char* definition);
  /// Compresses and writes the open chunk and its index records.
  void write_chunk();
  /// Writes the version line and the unindexed file header into the file just opened (or throws
  /// after closing it).
  void start();
  /// The file header record (padded to 4096 bytes as rosbag's).
  void append_file_header(std::vector<std::uint8_t>& out) const;
  void write_bytes(const std::vector<std::uint8_t>& bytes);
  /// Writes the pieces (at most 3), in order, with writev(2): one system call unless it is cut short.
  void write_bytes(std::initializer_list<std::pair<const void*, std::size_t>> pieces);
  [[noreturn]] void fail(const std::string& what) const;

  std::string path_;
  Compression compression_;
  std::uint32_t chunk_threshold_;  ///< [bytes]
  int descriptor_ = -1;  ///< the open file (write only); -1 once closed
  std::uint64_t position_ = 0;  ///< bytes written to the file so far
  std::uint64_t file_header_position_ = 0;
  std::uint64_t index_position_ = 0;  ///< where the connection and chunk-info records start (0: unindexed)
  std::vector<Connection> connections_;  ///< by id (= order of first appearance)
  std::vector<ChunkInfo> chunks_;
  bool chunk_open_ = false;
  bool broken_ = false;  ///< a chunk write failed part-way: the file ends in a partial chunk
  ChunkInfo open_chunk_{};
  std::vector<std::uint8_t> chunk_;        ///< uncompressed data of the open chunk
  std::vector<std::uint8_t> compressed_;   ///< the chunk compressed (reused)
  std::vector<std::uint8_t> records_;      ///< record headers and index records being written (reused)
  std::vector<std::uint8_t> chunk_header_;  ///< the chunk record's header and data length (reused)
};

}  // namespace birkhoff_cart
