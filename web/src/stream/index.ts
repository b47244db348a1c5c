/** The facemime bitstream decoder (docs/bitstream.md), for the browser receiver. */

export { crc32 } from './crc32';
export { readChunk, readLength, writeChunk, KIND_ACTOR, KIND_APPEARANCE, KIND_HEADER, KIND_INTER, KIND_INTRA,
  type Chunk, type ReadResult } from './chunks';
export { parseHeader, sameHeader, InvalidHeader, POSE_PARAMETERS, type Header } from './header';
export { StreamDecoder, MAX_GAP_PACKETS, type Event, type Frame, type Stats } from './decoder';
